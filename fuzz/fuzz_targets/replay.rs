//! MCAP reading plus CDR and Foxglove-JSON message decoding, as `marsupial replay` reads a
//! log: the bytes go through `Log::from_bytes` (the structural preflight, the summary or a
//! walk of the messages for the topic list), every topic is classified, the image and
//! odometry topics are chosen as the CLI chooses them, and the first messages of every
//! topic a replay reads are decoded to frames (raw and compressed pixels) or odometry.
//! A malformed file or message must give a typed error, never a panic, a hang or an
//! allocation out of proportion to the input (run with `-malloc_limit_mb=1024`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use marsupial::replay::decode;
use marsupial::replay::log::Log;
use marsupial::replay::topics::{TopicKind, choose, classify};
use std::collections::BTreeMap;
use std::path::Path;

/// Messages decoded per input: enough to reach every topic of a seed, few enough that
/// a file of many tiny messages stays fast.
const MAX_MESSAGES: usize = 64;

fuzz_target!(|data: &[u8]| {
    let log = match Log::from_bytes(Path::new("fuzz.mcap"), data.to_vec()) {
        Ok(log) => log,
        Err(e) => {
            std::hint::black_box(e.to_string());
            return;
        }
    };
    let mut kinds: BTreeMap<&str, TopicKind> = BTreeMap::new();
    for info in log.topics().values() {
        match classify(&info.schema, &info.encoding) {
            Ok(Some(kind)) => {
                kinds.insert(info.topic.as_str(), kind);
            }
            Ok(None) => {}
            Err(why) => {
                std::hint::black_box(why);
            }
        }
    }
    for odometry in [false, true] {
        if let Err(e) = choose(log.topics(), None, odometry, odometry) {
            std::hint::black_box(e.to_string());
        }
    }
    let wanted: Vec<&str> = kinds.keys().copied().collect();
    for message in log.messages(&wanted).take(MAX_MESSAGES) {
        let m = match message {
            Ok(m) => m,
            Err(e) => {
                std::hint::black_box(e.to_string());
                break;
            }
        };
        let Some(&kind) = kinds.get(m.topic) else {
            continue;
        };
        let outcome = if kind.is_image() {
            decode::frame(kind, &m.data).map(|f| {
                assert!(f.image.width() > 0 && f.image.height() > 0);
                f.image.width()
            })
        } else {
            decode::odometry(kind, &m.data).map(|o| o.stamp_ns.map_or(0, |s| s as usize))
        };
        match outcome {
            Ok(n) => {
                std::hint::black_box(n);
            }
            Err(e) => {
                std::hint::black_box((e.reason(), e.to_string()));
            }
        }
    }
});
