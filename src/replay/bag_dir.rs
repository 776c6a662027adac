//! A rosbag2 directory: `metadata.yaml` and the split files it names
//! (`ros2 bag record --max-bag-size`/`--max-bag-duration` writes several), so that
//! `marsupial replay DIR` reads a bag as `ros2 bag play DIR` does.
//!
//! Only the fields a replay needs are read from `metadata.yaml`, under its top-level
//! `rosbag2_bagfile_information`: `storage_identifier` (it must be `mcap`),
//! `relative_file_paths` (the files, in their order) and `compression_mode` (rosbag2's own
//! whole-file or per-message compression, which is refused by name). The reader is a
//! small one of its own, for the YAML rosbag2 writes: keys one indent below
//! `rosbag2_bagfile_information`, scalars plain or quoted, the file list in block
//! (`- a.mcap`) or flow (`[a.mcap, b.mcap]`) style. Everything else (topics, counts,
//! QoS text, nested maps) is skipped by its indentation. Every refusal names the field.

use super::ReplayError;
use std::path::{Path, PathBuf};

/// The top-level key of rosbag2's `metadata.yaml`.
const ROOT: &str = "rosbag2_bagfile_information";

/// The split files of the rosbag2 directory `dir`, in the order `metadata.yaml` gives.
///
/// # Errors
/// [`ReplayError::Bag`] when `metadata.yaml` is missing or malformed, the storage is not
/// MCAP, rosbag2 compressed the files itself, or a file it names is not there.
pub fn split_files(dir: &Path) -> Result<Vec<PathBuf>, ReplayError> {
    let meta = dir.join("metadata.yaml");
    let bag = |why: String| ReplayError::Bag {
        path: meta.clone(),
        why,
    };
    let text = std::fs::read_to_string(&meta).map_err(|e| {
        bag(format!(
            "cannot read it ({e}): a directory is replayed as a rosbag2 bag, whose metadata.yaml names its files"
        ))
    })?;
    let fields = Fields::parse(&text).map_err(bag)?;
    let storage = fields.scalar("storage_identifier").map_err(bag)?;
    if storage != "mcap" {
        return Err(bag(format!(
            "`storage_identifier` is `{storage}`: only MCAP bags are read (convert it with `ros2 bag convert`, storage `mcap`)"
        )));
    }
    if let Ok(mode) = fields.scalar("compression_mode")
        && !matches!(mode.to_ascii_lowercase().as_str(), "" | "none")
    {
        return Err(bag(format!(
            "`compression_mode` is `{mode}`: rosbag2's own compression of whole files or messages is not read (re-write the bag uncompressed with `ros2 bag convert`; MCAP's compressed chunks are read)"
        )));
    }
    let names = fields.list("relative_file_paths").map_err(bag)?;
    if names.is_empty() {
        return Err(bag("`relative_file_paths` is empty".into()));
    }
    names
        .iter()
        .map(|name| {
            let file = dir.join(name);
            if file.is_file() {
                return Ok(file);
            }
            // Older rosbag2 wrote the paths with the bag directory's name in front.
            let bare = Path::new(name).file_name().map(|f| dir.join(f));
            bare.filter(|f| f.is_file()).ok_or_else(|| {
                bag(format!(
                    "`relative_file_paths` names `{name}`, which is not in {}",
                    dir.display()
                ))
            })
        })
        .collect()
}

/// The lines one indent below [`ROOT`]: each key with what follows it on its line, and
/// the more indented lines after it.
struct Fields<'t> {
    entries: Vec<(&'t str, &'t str, Vec<&'t str>)>,
}

impl<'t> Fields<'t> {
    fn parse(text: &'t str) -> Result<Self, String> {
        let mut lines = text
            .lines()
            .map(|l| l.trim_end())
            .filter(|l| !l.trim_start().is_empty() && !l.trim_start().starts_with('#') && *l != "---");
        let root = format!("{ROOT}:");
        if !lines.by_ref().any(|l| l == root) {
            return Err(format!("no `{ROOT}` at the top level: not a rosbag2 metadata.yaml"));
        }
        let indent = |l: &str| l.len() - l.trim_start().len();
        let mut entries: Vec<(&str, &str, Vec<&str>)> = Vec::new();
        let mut child = None;
        for line in lines {
            let at = indent(line);
            if at == 0 {
                break;
            }
            let child = *child.get_or_insert(at);
            if at < child {
                return Err(format!(
                    "line `{}` is indented less than the fields of `{ROOT}`",
                    line.trim()
                ));
            }
            let item = line.trim_start();
            if at == child && !item.starts_with("- ") && item != "-" {
                let Some((key, rest)) = item.split_once(':') else {
                    return Err(format!("line `{item}` is not `key: value`"));
                };
                entries.push((key.trim(), rest.trim(), Vec::new()));
            } else if let Some((_, _, more)) = entries.last_mut() {
                more.push(item);
            }
        }
        Ok(Self { entries })
    }

    fn entry(&self, key: &str) -> Result<&(&'t str, &'t str, Vec<&'t str>), String> {
        self.entries
            .iter()
            .find(|(k, _, _)| *k == key)
            .ok_or_else(|| format!("no `{key}` in `{ROOT}`"))
    }

    /// A scalar field.
    fn scalar(&self, key: &str) -> Result<String, String> {
        let (_, rest, _) = self.entry(key)?;
        scalar(rest).map_err(|why| format!("`{key}`: {why}"))
    }

    /// A list of scalars, in block or flow style.
    fn list(&self, key: &str) -> Result<Vec<String>, String> {
        let (_, rest, more) = self.entry(key)?;
        let named = |why: String| format!("`{key}`: {why}");
        if let Some(flow) = rest.strip_prefix('[') {
            let Some(inner) = strip_comment(flow).trim_end().strip_suffix(']') else {
                return Err(named("a flow list `[…]` must end on its line".into()));
            };
            return inner
                .split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(|s| scalar(s).map_err(named))
                .collect();
        }
        if !strip_comment(rest).trim().is_empty() {
            return Err(named(format!("`{rest}` is not a list")));
        }
        let mut items = Vec::new();
        for line in more {
            match line.strip_prefix("- ") {
                Some(item) => items.push(scalar(item.trim()).map_err(named)?),
                // Deeper lines belong to the item above (a list of maps is not a list of
                // file names).
                None => return Err(named(format!("`{line}` is not a file name"))),
            }
        }
        Ok(items)
    }
}

/// A line's text before a ` #` comment (outside quotes: file names here have none).
fn strip_comment(s: &str) -> &str {
    if s.starts_with('"') || s.starts_with('\'') {
        return s;
    }
    s.find(" #").map_or(s, |i| &s[..i]).trim_end()
}

/// A plain, single-quoted or double-quoted scalar on one line.
fn scalar(raw: &str) -> Result<String, String> {
    let raw = raw.trim();
    if let Some(body) = raw.strip_prefix('\'') {
        let Some(body) = body.strip_suffix('\'') else {
            return Err(format!("`{raw}`: a quoted value must end on its line"));
        };
        return Ok(body.replace("''", "'"));
    }
    if let Some(body) = raw.strip_prefix('"') {
        let Some(body) = body.strip_suffix('"') else {
            return Err(format!("`{raw}`: a quoted value must end on its line"));
        };
        let mut out = String::new();
        let mut chars = body.chars();
        while let Some(c) = chars.next() {
            if c != '\\' {
                out.push(c);
                continue;
            }
            match chars.next() {
                Some(e @ ('"' | '\\' | '/')) => out.push(e),
                Some('t') => out.push('\t'),
                other => return Err(format!("`{raw}`: escape `\\{}` is not read here", other.unwrap_or(' '))),
            }
        }
        return Ok(out);
    }
    let plain = strip_comment(raw);
    if plain.starts_with(['|', '>', '{', '[', '&', '*', '!']) {
        return Err(format!("`{plain}` is not a plain value"));
    }
    Ok(if plain == "~" || plain == "null" {
        String::new()
    } else {
        plain.to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What rosbag2 (Jazzy, version 9) writes, cut to what matters plus a nested map, a
    /// list of maps and a QoS string that would confuse a careless reader.
    const META: &str = "
rosbag2_bagfile_information:
  version: 9
  storage_identifier: mcap
  duration:
    nanoseconds: 2000000000
  topics_with_message_count:
    - topic_metadata:
        name: /cam
        offered_qos_profiles: \"- history: 3\\n  depth: 0\\n\"
      message_count: 4
  compression_format: \"\"
  compression_mode: \"\"
  relative_file_paths:
    - bag_0.mcap
    - 'bag_1.mcap'
  files:
    - path: bag_0.mcap
      message_count: 2
  custom_data: ~
";

    #[test]
    fn reads_the_fields_a_replay_needs() {
        let f = Fields::parse(META).unwrap();
        assert_eq!(f.scalar("storage_identifier").unwrap(), "mcap");
        assert_eq!(f.scalar("compression_mode").unwrap(), "");
        assert_eq!(f.list("relative_file_paths").unwrap(), ["bag_0.mcap", "bag_1.mcap"]);
        let flow = META.replace(
            "relative_file_paths:\n    - bag_0.mcap\n    - 'bag_1.mcap'",
            "relative_file_paths: [bag_0.mcap, \"bag_1.mcap\"]",
        );
        let f = Fields::parse(&flow).unwrap();
        assert_eq!(f.list("relative_file_paths").unwrap(), ["bag_0.mcap", "bag_1.mcap"]);
    }

    #[test]
    fn refusals_name_the_field() {
        let f = Fields::parse(META).unwrap();
        assert!(f.list("files").unwrap_err().contains("`files`"));
        assert!(f.scalar("ros_distro").unwrap_err().contains("no `ros_distro`"));
        assert!(Fields::parse("foo: 1\n").err().unwrap().contains(ROOT));
        let bad = META.replace("  storage_identifier: mcap", "  storage_identifier: \"mcap");
        let f = Fields::parse(&bad).unwrap();
        assert!(
            f.scalar("storage_identifier")
                .unwrap_err()
                .contains("`storage_identifier`")
        );
    }
}
