//! `runs.jsonl` resume parsing, as `trials --resume` runs it: arbitrary bytes checked
//! against the runs of `scenarios/bujold-table1.toml` by `campaign::parse_resumable` (the
//! body of `read_resumable`). Besides never panicking, a kept prefix must be whole lines
//! of the campaign's first runs, and kept plus torn bytes must be the whole file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marsupial::sim::campaign::parse_resumable;
use marsupial::sim::scenario::{RunSpec, Scenario};
use std::path::Path;
use std::sync::OnceLock;

fn runs() -> &'static [RunSpec] {
    static RUNS: OnceLock<Vec<RunSpec>> = OnceLock::new();
    RUNS.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/bujold-table1.toml");
        let loaded = Scenario::load(&path).expect("shipped scenario");
        loaded.scenario.runs(&loaded.profile)
    })
}

fuzz_target!(|data: &[u8]| {
    let runs = runs();
    match parse_resumable(data, Path::new("runs.jsonl"), runs) {
        Ok(r) => {
            let keep = r.keep_bytes as usize;
            assert_eq!(keep + r.torn_bytes as usize, data.len());
            assert!(keep == 0 || data[keep - 1] == b'\n');
            assert_eq!(data[..keep].iter().filter(|&&b| b == b'\n').count(), r.records.len());
            for (rec, spec) in r.records.iter().zip(runs) {
                assert_eq!((rec.index, rec.seed), (spec.index, spec.seed));
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
});
