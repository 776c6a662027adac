//! Bags as users' recorders write them, replayed in the default build: chunks compressed
//! with zstd (libmcap's default, so rosbag2's MCAP storage's, and Foxglove's) and lz4, and
//! rosbag2 directories of split files named by `metadata.yaml`.
//!
//! The compressed bags are the real-photo bag of `replay.rs`, written uncompressed by the
//! `mcap` crate, with each chunk's records re-encoded here by pure-Rust encoders (ruzstd,
//! lz4_flex): the reader's decoders are not used to make them. Their summary keeps its
//! schemas, channels and statistics; chunk indexes and summary offsets, which would point
//! at the old offsets, are left out. The figure: the percepts, commands and every other
//! per-frame output of a replay are the same, value for value, from each compressed copy
//! as from the uncompressed bag.

use crate::common::photos;
use crate::replay::{DT, Msg, T0, expected, of_kind, opts, photo_bag, replay, replay_err, tmp, write_bag};
use marsupial::replay::ReplayError;
use marsupial::replay::log::LogFault;
use std::io::Write;
use std::path::Path;

const MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

fn record(out: &mut Vec<u8>, op: u8, body: &[u8]) {
    out.push(op);
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(body);
}

fn zstd(data: &[u8]) -> Vec<u8> {
    ruzstd::encoding::compress_to_vec(data, ruzstd::encoding::CompressionLevel::Fastest)
}

fn lz4(data: &[u8]) -> Vec<u8> {
    let mut e = lz4_flex::frame::FrameEncoder::new(Vec::new());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

/// `src` (an MCAP file with uncompressed chunks) with every chunk's records encoded by
/// `encode` and the chunk named `name`; returns the file and where each chunk's
/// compressed data lies in it.
fn recompress(src: &[u8], name: &str, encode: fn(&[u8]) -> Vec<u8>) -> (Vec<u8>, Vec<std::ops::Range<usize>>) {
    let footer_at = src.len() - MAGIC.len() - 29;
    let summary_at = u64_at(src, footer_at + 9) as usize;
    let mut out = MAGIC.to_vec();
    let (mut new_summary, mut chunks) = (0, Vec::new());
    let mut at = MAGIC.len();
    while at < footer_at {
        if at == summary_at {
            new_summary = out.len();
        }
        let (op, len) = (src[at], u64_at(src, at + 1) as usize);
        let body = &src[at + 9..at + 9 + len];
        let in_summary = summary_at != 0 && at >= summary_at;
        match op {
            0x06 => {
                let name_len = u32::from_le_bytes(body[28..32].try_into().unwrap()) as usize;
                assert_eq!(name_len, 0, "the source's chunks are uncompressed");
                let records = &body[32 + 8..];
                let data = encode(records);
                // Start and end times, uncompressed size; the CRC of the records as they are.
                let mut b = body[..24].to_vec();
                b.extend_from_slice(&crc32fast::hash(records).to_le_bytes());
                b.extend_from_slice(&(name.len() as u32).to_le_bytes());
                b.extend_from_slice(name.as_bytes());
                b.extend_from_slice(&(data.len() as u64).to_le_bytes());
                let start = out.len() + 9 + b.len();
                b.extend_from_slice(&data);
                record(&mut out, op, &b);
                chunks.push(start..start + data.len());
            }
            0x0F => record(&mut out, op, &[0; 4]), // data end: its CRC is of the old bytes
            0x08 | 0x0A | 0x0D | 0x0E if in_summary => {}
            _ => record(&mut out, op, body),
        }
        at += 9 + len;
    }
    let mut footer = (new_summary as u64).to_le_bytes().to_vec();
    footer.extend_from_slice(&[0; 12]);
    record(&mut out, 0x02, &footer);
    out.extend_from_slice(MAGIC);
    (out, chunks)
}

/// The replay's output lines of `log` for the image topic `topic`, with the behavior or
/// the schema alone.
fn lines_of(log: &Path, topic: &str, behavior: bool) -> Vec<serde_json::Value> {
    let mut o = opts(log);
    o.image_topic = Some(topic.into());
    o.behavior = behavior;
    let (lines, r) = replay(&o);
    r.unwrap_or_else(|e| panic!("{}: {e}", log.display()));
    lines
}

#[test]
fn zstd_and_lz4_bags_of_real_photos_replay_as_the_uncompressed_bag() {
    let Some(dir) = photos() else { return };
    let d = tmp("bags-compressed");
    let plain = d.join("plain.mcap");
    let (frames, _) = photo_bag(&plain, &dir);
    let bytes = std::fs::read(&plain).unwrap();
    for (name, encode) in [("zstd", zstd as fn(&[u8]) -> Vec<u8>), ("lz4", lz4)] {
        let (packed, chunks) = recompress(&bytes, name, encode);
        assert!(!chunks.is_empty());
        assert!(packed.len() < bytes.len() * 9 / 10, "{name}: the chunks are compressed");
        let bag = d.join(format!("{name}.mcap"));
        std::fs::write(&bag, &packed).unwrap();
        let mut identical = 0;
        for topic in ["/camera/image_raw", "/camera/image_raw/compressed"] {
            for behavior in [false, true] {
                let want = lines_of(&plain, topic, behavior);
                let got = lines_of(&bag, topic, behavior);
                assert_eq!(of_kind(&got, "frame").len(), 4, "{name} {topic}");
                assert_eq!(got, want, "{name} {topic} behavior {behavior}");
                identical += of_kind(&got, "frame").len();
            }
        }
        // The percepts are the schema's on the very pixels, as from the plain bag.
        let raw = lines_of(&bag, "/camera/image_raw", false);
        let got: Vec<_> = of_kind(&raw, "frame").iter().map(|l| l["percept"].clone()).collect();
        assert_eq!(got, expected(&frames));
        assert!(of_kind(&raw, "frame").iter().any(|l| l["found"] == true));
        eprintln!(
            "figure: {name} bag ({} of {} bytes, {} chunks): {identical} frames, each identical to the uncompressed bag's",
            packed.len(),
            bytes.len(),
            chunks.len()
        );
    }
}

/// The error of replaying `bytes` (written to `name` in `d`).
fn error_of(d: &Path, name: &str, bytes: &[u8]) -> (Vec<serde_json::Value>, ReplayError) {
    let bag = d.join(name);
    std::fs::write(&bag, bytes).unwrap();
    replay_err(&bag)
}

/// A small bag of 32×24 frames on `/cam` in 10 kB chunks (several chunks).
fn small(path: &Path, n: u64) {
    let msgs: Vec<Msg> = (0..n).map(|k| ("/cam", T0 + k * DT, crate::replay::good(k))).collect();
    write_bag(path, &[("/cam", "sensor_msgs/msg/Image")], &msgs);
}

#[test]
fn a_corrupt_or_unknown_compressed_chunk_is_an_error_naming_it() {
    let d = tmp("bags-corrupt");
    let plain = d.join("plain.mcap");
    small(&plain, 3);
    let bytes = std::fs::read(&plain).unwrap();
    let (packed, chunks) = recompress(&bytes, "zstd", zstd);

    // Bytes of the zstd data overwritten: the decoder or the chunk's CRC refuses it.
    let mut bad = packed.clone();
    let mid = chunks[0].start + chunks[0].len() / 2;
    bad[mid..mid + 8].copy_from_slice(&[0xA5; 8]);
    let (lines, e) = error_of(&d, "bad.mcap", &bad);
    assert!(
        matches!(
            &e,
            ReplayError::Log {
                fault: LogFault::Corrupt { after: None, .. },
                ..
            }
        ),
        "{e:?}"
    );
    let text = e.to_string().to_lowercase();
    assert!(text.contains("zstd") || text.contains("crc"), "{text}");
    assert_eq!(of_kind(&lines, "summary")[0]["frames"], 0);

    // Cut inside a compressed chunk's data: the frames of the chunks before it, then
    // truncated, not a panic.
    let long = d.join("long.mcap");
    small(&long, 120);
    let (long, chunks) = recompress(&std::fs::read(&long).unwrap(), "zstd", zstd);
    assert!(chunks.len() > 1);
    let cut = chunks[1].start + chunks[1].len() / 2;
    let (lines, e) = error_of(&d, "cut.mcap", &long[..cut]);
    let frames = of_kind(&lines, "frame").len() as u64;
    assert!(frames > 0 && frames < 120, "{frames}");
    assert!(
        matches!(&e, ReplayError::Log { fault: LogFault::Truncated { after: Some((t, i)) }, .. } if t == "/cam" && *i == frames - 1),
        "{e:?}"
    );

    // A codec no writer uses is refused by its name, saying what is read.
    let (unknown, _) = recompress(&bytes, "brotli", |b| b.to_vec());
    let (_, e) = error_of(&d, "brotli.mcap", &unknown);
    assert!(
        matches!(&e, ReplayError::Log { fault: LogFault::Compression { compression, after: None }, .. } if compression == "brotli"),
        "{e:?}"
    );
    assert!(e.to_string().contains("only zstd, lz4 and uncompressed"), "{e}");

    // Records inside a decompressed chunk get the file's structural check: a channel
    // topic declared longer than its record is refused before it is parsed.
    let mut evil = bytes.clone();
    let topic_len = evil.windows(8).position(|w| w == b"\x04\x00\x00\x00/cam").unwrap();
    evil[topic_len..topic_len + 4].copy_from_slice(&0x7fff_0000u32.to_le_bytes());
    // The plain file is refused by the preflight, the zstd one once its chunk is decoded.
    let (_, e) = error_of(&d, "evil-plain.mcap", &evil);
    assert!(
        matches!(
            &e,
            ReplayError::Log {
                fault: LogFault::Malformed(_),
                ..
            }
        ),
        "{e:?}"
    );
    let (evil, _) = recompress(&evil, "zstd", zstd);
    let (_, e) = error_of(&d, "evil.mcap", &evil);
    assert!(
        matches!(
            &e,
            ReplayError::Log {
                fault: LogFault::MalformedChunk { .. },
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("declares a 2147418112-byte string"), "{e}");
}

const META: &str = "rosbag2_bagfile_information:
  version: 9
  storage_identifier: STORAGE
  duration:
    nanoseconds: 400000000
  starting_time:
    nanoseconds_since_epoch: 1700000000000000000
  message_count: 12
  topics_with_message_count:
    - topic_metadata:
        name: /camera/image_raw
        type: sensor_msgs/msg/Image
        serialization_format: cdr
        offered_qos_profiles:
          - history: keep_last
            depth: 10
      message_count: 4
  compression_format: \"\"
  compression_mode: \"\"
  relative_file_paths:
FILES
  files:
    - path: bag_0.mcap
      starting_time:
        nanoseconds_since_epoch: 1700000000000000000
      duration:
        nanoseconds: 200000000
      message_count: 6
  custom_data: ~
  ros_distro: jazzy
";

fn meta(storage: &str, files: &[&str]) -> String {
    let list: Vec<String> = files.iter().map(|f| format!("    - {f}")).collect();
    META.replace("STORAGE", storage).replace("FILES", &list.join("\n"))
}

#[test]
fn a_rosbag2_directory_of_split_files_replays_as_one_bag() {
    let Some(dir) = photos() else { return };
    let d = tmp("bags-dir");
    let whole = d.join("whole.mcap");
    photo_bag(&whole, &dir);
    // The same messages split in two files, the second zstd-chunked, as a rosbag2
    // recorder with `--max-bag-size` would.
    let bag = d.join("bag");
    std::fs::create_dir_all(&bag).unwrap();
    let msgs: Vec<(String, u64, Vec<u8>)> = {
        let mut out = Vec::new();
        for m in mcap::MessageStream::new(&std::fs::read(&whole).unwrap()).unwrap() {
            let m = m.unwrap();
            out.push((m.channel.topic.clone(), m.log_time, m.data.into_owned()));
        }
        out
    };
    let topics = [
        ("/camera/image_raw", "sensor_msgs/msg/Image"),
        ("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage"),
        ("/odom", "nav_msgs/msg/Odometry"),
    ];
    let leak = |(t, ns, m): &(String, u64, Vec<u8>)| -> Msg {
        let t = topics.iter().find(|(n, _)| n == t).unwrap().0;
        (t, *ns, m.clone())
    };
    let (first, second) = msgs.split_at(6);
    write_bag(
        &bag.join("bag_0.mcap"),
        &topics,
        &first.iter().map(leak).collect::<Vec<_>>(),
    );
    let part = bag.join("part.mcap");
    write_bag(&part, &topics, &second.iter().map(leak).collect::<Vec<_>>());
    let (packed, _) = recompress(&std::fs::read(&part).unwrap(), "zstd", zstd);
    std::fs::write(bag.join("bag_1.mcap"), packed).unwrap();
    std::fs::remove_file(&part).unwrap();
    std::fs::write(bag.join("metadata.yaml"), meta("mcap", &["bag_0.mcap", "bag_1.mcap"])).unwrap();

    for (topic, behavior) in [
        ("/camera/image_raw", false),
        ("/camera/image_raw", true),
        ("/camera/image_raw/compressed", true),
    ] {
        let want = lines_of(&whole, topic, behavior);
        let got = lines_of(&bag, topic, behavior);
        let idx: Vec<_> = of_kind(&got, "frame").iter().map(|l| l["index"].clone()).collect();
        assert_eq!(idx, [0, 1, 2, 3], "numbered across the files");
        assert_eq!(got, want, "{topic} behavior {behavior}");
    }

    // In the other order, the frames come in that order.
    std::fs::write(bag.join("metadata.yaml"), meta("mcap", &["bag_1.mcap", "bag_0.mcap"])).unwrap();
    let got = lines_of(&bag, "/camera/image_raw", false);
    let t: Vec<f64> = of_kind(&got, "frame")
        .iter()
        .map(|l| l["t"].as_f64().unwrap())
        .collect();
    assert!(t[0] > t[3], "{t:?}");

    // A file named but missing is named.
    std::fs::write(bag.join("metadata.yaml"), meta("mcap", &["bag_0.mcap", "bag_2.mcap"])).unwrap();
    let (_, e) = replay_err(&bag);
    let text = e.to_string();
    assert!(matches!(e, ReplayError::Bag { .. }), "{e:?}");
    assert!(
        text.contains("`bag_2.mcap`") && text.contains("relative_file_paths"),
        "{text}"
    );

    // Another storage is refused, saying only MCAP is read.
    std::fs::write(bag.join("metadata.yaml"), meta("sqlite3", &["bag_0.db3"])).unwrap();
    let (_, e) = replay_err(&bag);
    let text = e.to_string();
    assert!(text.contains("`sqlite3`") && text.contains("only MCAP"), "{text}");

    // rosbag2's own file compression, and a metadata.yaml without the file list.
    let filed = meta("mcap", &["bag_0.mcap"]).replace("compression_mode: \"\"", "compression_mode: FILE");
    std::fs::write(bag.join("metadata.yaml"), filed).unwrap();
    let (_, e) = replay_err(&bag);
    assert!(e.to_string().contains("`compression_mode` is `FILE`"), "{e}");
    let listless = meta("mcap", &[]).replace("  relative_file_paths:\n\n", "");
    std::fs::write(bag.join("metadata.yaml"), listless).unwrap();
    let (_, e) = replay_err(&bag);
    assert!(e.to_string().contains("no `relative_file_paths`"), "{e}");
}

#[test]
fn a_bag_of_real_photos_from_the_python_mcap_packages_defaults_replays() {
    // Written by another implementation (Python's `mcap` package, whose `Writer` makes
    // zstd chunks by default): before, the default build read 0 frames of it.
    let Some(dir) = photos() else { return };
    let d = tmp("bags-python");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/replay/python_bag.py");
    let ran = std::process::Command::new("python3")
        .arg(&script)
        .arg(&d)
        .arg(&dir)
        .status();
    match ran.map(|s| s.code()) {
        Ok(Some(0)) => {}
        Ok(Some(3)) | Err(_) => {
            eprintln!("skipping: python3 with the `mcap` and `zstandard` packages is not here");
            return;
        }
        other => panic!("{} failed: {other:?}", script.display()),
    }
    let defaults = d.join("defaults.mcap");
    let bytes = std::fs::read(&defaults).unwrap();
    assert!(
        bytes.windows(4).any(|w| w == b"zstd"),
        "the Writer's default chunks are zstd"
    );
    let topic = "/camera/image_raw/compressed";
    let got = lines_of(&defaults, topic, false);
    let want = lines_of(&d.join("plain.mcap"), topic, false);
    assert_eq!(of_kind(&got, "frame").len(), 4);
    assert_eq!(got, want);
    eprintln!("figure: Python mcap defaults (zstd): 4 frames, each identical to the uncompressed twin's");
}
