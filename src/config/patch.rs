//! Patching one TOML document with another: how a scenario varies a profile without
//! copying it.
//!
//! A copied profile drifts: a tuning change to `profiles/bujold.toml` would silently miss
//! the copy an experiment runs on. A scenario's `[profile_patch]` instead names only what
//! the experiment changes (`fiducial.two_block.right_color = "yellow"`), and everything
//! else follows the profile.
//!
//! Merging is by key: a table in the patch merges into the table of the same name, any
//! other value (a number, a string, an array, an array of tables) replaces the base's
//! value whole. The base's comments and layout are kept (edited with `toml_edit`), except
//! a replaced value's trailing comment, which described the old value.

use toml_edit::{DocumentMut, Item, Table, TableLike};

/// `base` (TOML text) with `patch` merged in, as TOML text.
///
/// # Errors
/// A message when `base` is not valid TOML, or when the patch would merge a table into a
/// value that is not a table (`drive = 3` patched with `[drive] kind = …`).
pub fn patched(base: &str, patch: &toml::Table) -> Result<String, String> {
    let mut doc: DocumentMut = base
        .parse()
        .map_err(|e: toml_edit::TomlError| e.message().to_string())?;
    let patch_text = toml::to_string(patch).map_err(|e| e.to_string())?;
    let patch_doc: DocumentMut = patch_text
        .parse()
        .map_err(|e: toml_edit::TomlError| e.message().to_string())?;
    merge(doc.as_table_mut(), patch_doc.as_table(), "")?;
    Ok(doc.to_string())
}

fn merge(base: &mut Table, patch: &dyn TableLike, path: &str) -> Result<(), String> {
    for (key, item) in patch.iter() {
        let here = if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        };
        match (base.get_mut(key), item.as_table_like()) {
            // A table (standard or inline) merges; anything else, arrays of tables
            // included, is not table-like and replaces.
            (Some(existing), Some(patch_table)) => {
                if existing.is_inline_table() {
                    // Widen an inline table to a standard one so keys can be merged in.
                    let t = existing.as_inline_table().cloned().unwrap_or_default().into_table();
                    *existing = Item::Table(t);
                }
                let Some(target) = existing.as_table_mut() else {
                    return Err(format!(
                        "`{here}` is not a table in the profile, so a table cannot patch it"
                    ));
                };
                merge(target, patch_table, &here)?;
            }
            // Replacing in place keeps the key's leading comments (they usually describe a
            // section); the old value's trailing comment goes with it.
            (Some(existing), _) => *existing = item.clone(),
            (None, _) => {
                base.insert(key, item.clone());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(src: &str) -> toml::Table {
        src.parse().unwrap()
    }

    #[test]
    fn merges_tables_by_key_and_replaces_values() {
        let base = "# Bujold\nname = \"a\"\n\n[drive]\nkind = \"x\" # why\nspeed = 1.0\n\n[[cameras]]\nw = 1\n";
        let out = patched(
            base,
            &table("name = \"b\"\n[drive]\nspeed = 2.0\n[fiducial]\nright = \"yellow\"\n"),
        )
        .unwrap();
        let v: toml::Table = out.parse().unwrap();
        assert_eq!(v["name"].as_str(), Some("b"));
        assert_eq!(v["drive"]["kind"].as_str(), Some("x"), "untouched keys stay");
        assert_eq!(v["drive"]["speed"].as_float(), Some(2.0));
        assert_eq!(v["fiducial"]["right"].as_str(), Some("yellow"));
        assert_eq!(v["cameras"][0]["w"].as_integer(), Some(1));
        assert!(
            out.contains("# Bujold") && out.contains("# why"),
            "comments kept:\n{out}"
        );
    }

    #[test]
    fn arrays_are_replaced_whole_and_inline_tables_merge() {
        let base = "a = [1, 2, 3]\nm = { x = 1, y = 2 }\n";
        let out = patched(base, &table("a = [4]\n[m]\ny = 5\n")).unwrap();
        let v: toml::Table = out.parse().unwrap();
        assert_eq!(v["a"].as_array().unwrap().len(), 1);
        assert_eq!(v["m"]["x"].as_integer(), Some(1));
        assert_eq!(v["m"]["y"].as_integer(), Some(5));
        // An array of tables is replaced whole too, not merged element by element.
        let base = "[[cameras]]\nw = 1\nh = 1\n\n[[cameras]]\nw = 3\n";
        let out = patched(base, &table("[[cameras]]\nw = 2\n")).unwrap();
        let v: toml::Table = out.parse().unwrap();
        let cams = v["cameras"].as_array().unwrap();
        assert_eq!(cams.len(), 1);
        assert_eq!(cams[0]["w"].as_integer(), Some(2));
        assert!(cams[0].get("h").is_none(), "{out}");
    }

    #[test]
    fn a_table_cannot_patch_a_value() {
        let e = patched("drive = 3\n", &table("[drive]\nkind = \"x\"\n")).unwrap_err();
        assert!(e.contains("`drive` is not a table"), "{e}");
        assert!(patched("a = [", &toml::Table::new()).is_err());
    }
}
