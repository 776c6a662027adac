//! Profile and scenario parse plus validate, as `marsupial check` runs them: arbitrary
//! bytes, as UTF-8, through both parsers; a scenario's `[profile_patch]` is merged into
//! a shipped profile and that profile validated, as `Scenario::load` does. Every error is
//! formatted, as the CLI prints it. Any panic is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marsupial::config::{self, patch};
use marsupial::profile::Profile;
use marsupial::sim::scenario::Scenario;
use std::path::Path;

/// The profile a fuzzed scenario's `[profile_patch]` is merged into.
const BASE_PROFILE: &str = include_str!("../../profiles/bujold.toml");

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("fuzz.toml");
    if let Err(e) = Profile::parse(src, file) {
        std::hint::black_box(e.to_string());
    }
    match config::parse_str::<Scenario>(src, file) {
        Ok(s) => {
            if let Some(p) = &s.profile_patch {
                match patch::patched(BASE_PROFILE, p) {
                    Ok(text) => {
                        if let Err(e) = Profile::parse(&text, Path::new("patched.toml")) {
                            std::hint::black_box(e.to_string());
                        }
                    }
                    Err(e) => {
                        std::hint::black_box(e);
                    }
                }
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
});
