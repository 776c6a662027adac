//! Errors for TOML configuration files (profiles and scenarios).

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;
use thiserror::Error;

/// One thing wrong with a configuration file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Dotted field path, e.g. `drive.d_min_m` or `cameras[0].width_px`; empty for
    /// whole-file syntax errors.
    pub path: String,
    /// 1-based line in the file, when known.
    pub line: Option<usize>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(l) = self.line {
            write!(f, "line {l}: ")?;
        }
        if !self.path.is_empty() {
            write!(f, "{}: ", self.path)?;
        }
        f.write_str(&self.message)
    }
}

/// A configuration file could not be read, parsed or validated.
#[derive(Debug, Clone, Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("{}: cannot read file: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The I/O error.
        #[source]
        source: Arc<std::io::Error>,
    },
    /// The file is not valid: syntax, unknown or missing fields, wrong types, or values
    /// out of range. Every problem found is listed.
    #[error("{}", render(file, problems))]
    Invalid {
        /// The file.
        file: PathBuf,
        /// What is wrong, in file order where known.
        problems: Vec<Problem>,
    },
}

impl ConfigError {
    /// The problems (empty for I/O errors).
    pub fn problems(&self) -> &[Problem] {
        match self {
            ConfigError::Io { .. } => &[],
            ConfigError::Invalid { problems, .. } => problems,
        }
    }
}

fn render(file: &std::path::Path, problems: &[Problem]) -> String {
    let mut s = String::new();
    for (i, p) in problems.iter().enumerate() {
        if i > 0 {
            s.push('\n');
        }
        s.push_str(&file.display().to_string());
        if let Some(l) = p.line {
            s.push_str(&format!(":{l}"));
        }
        s.push_str(": ");
        if !p.path.is_empty() {
            s.push_str(&p.path);
            s.push_str(": ");
        }
        s.push_str(&p.message);
    }
    s
}
