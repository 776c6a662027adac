//! Loading TOML configuration (profiles, scenarios) with errors a person can act on.
//!
//! Every error names the file, the field path (`cameras[0].hfov_deg`), the line where it
//! can be found, and what was expected. Unknown fields are rejected (every config struct
//! is `deny_unknown_fields`); semantic checks run after parsing and report every problem
//! at once, not just the first.

pub mod error;
#[cfg(feature = "sim")]
pub mod patch;
pub mod validate;

pub use error::{ConfigError, Problem};
pub use validate::{Validate, Validator, line_of_offset};

use serde::de::DeserializeOwned;
use std::path::Path;
use std::sync::Arc;

/// Parses and validates `src` (the contents of `file`, used in messages).
///
/// # Errors
/// [`ConfigError::Invalid`] listing syntax, schema and range problems.
pub fn parse_str<T: DeserializeOwned + Validate>(src: &str, file: &Path) -> Result<T, ConfigError> {
    let invalid = |problems| ConfigError::Invalid {
        file: file.to_path_buf(),
        problems,
    };
    let doc = match toml::de::DeTable::parse(src) {
        Ok(d) => d,
        Err(e) => {
            let line = e.span().map(|s| line_of_offset(src, s.start));
            return Err(invalid(vec![Problem {
                path: String::new(),
                line,
                message: format!("TOML syntax error: {}", e.message().trim()),
            }]));
        }
    };
    let de = toml::de::Deserializer::from(doc.clone());
    let value: T = match serde_path_to_error::deserialize(de) {
        Ok(v) => v,
        Err(e) => {
            let path = e.path().to_string();
            let path = if path == "." { String::new() } else { path };
            let inner = e.into_inner();
            let validator = Validator::new(src, Some(doc.get_ref()));
            let line = inner
                .span()
                .filter(|s| s.start > 0 || s.end > 0)
                .map(|s| line_of_offset(src, s.start))
                .or_else(|| validator.line_of(&path));
            return Err(invalid(vec![Problem {
                path,
                line,
                message: inner.message().trim().to_string(),
            }]));
        }
    };
    let mut v = Validator::new(src, Some(doc.get_ref()));
    value.validate(&mut v);
    let problems = v.into_problems();
    if problems.is_empty() {
        Ok(value)
    } else {
        Err(invalid(problems))
    }
}

/// Reads, parses and validates a TOML file.
///
/// # Errors
/// [`ConfigError::Io`] when the file cannot be read (or is not UTF-8), otherwise as
/// [`parse_str`].
pub fn load<T: DeserializeOwned + Validate>(path: &Path) -> Result<T, ConfigError> {
    parse_str(&read_source(path)?, path)
}

/// Reads a configuration file's text.
///
/// # Errors
/// [`ConfigError::Io`] when the file cannot be read (or is not UTF-8).
pub fn read_source(path: &Path) -> Result<String, ConfigError> {
    std::fs::read_to_string(path).map_err(|e| ConfigError::Io {
        file: path.to_path_buf(),
        source: Arc::new(e),
    })
}
