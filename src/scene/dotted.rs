//! Dotted paths into a scene's TOML document, as sweeps and the Python module name a
//! parameter: tables by key, arrays of tables (`material`, `generate`, `wall`, `stage`,
//! `grain`) by the `name` of an entry or by index, e.g. `material.sand.mu_s` or
//! `stage.0.duration`.

/// What to do about a path that names nothing, for the error that reports it.
pub const FIX: &str = "fix: name a key of the scene (tables by key, [[arrays]] by name or index)";

/// The table that holds the last key of `path` (split at dots), and that key.
fn parent<'d>(doc: &'d mut toml::Table, path: &str) -> Result<(&'d mut toml::Table, String), String> {
    let parts: Vec<&str> = path.split('.').collect();
    let mut here: &mut toml::Table = doc;
    let mut i = 0;
    while i + 1 < parts.len() {
        let key = parts[i];
        let entry = here.get_mut(key).ok_or_else(|| format!("the scene has no `{key}`"))?;
        here = match entry {
            toml::Value::Table(t) => t,
            toml::Value::Array(items) => {
                i += 1;
                let sel = parts[i];
                let found = match sel.parse::<usize>() {
                    Ok(k) => items.get_mut(k),
                    Err(_) => items.iter_mut().find(|it| it.get("name").and_then(|n| n.as_str()) == Some(sel)),
                };
                match found {
                    Some(toml::Value::Table(t)) => t,
                    _ => return Err(format!("`{key}` has no entry named or numbered `{sel}`")),
                }
            }
            _ => return Err(format!("`{key}` is not a table")),
        };
        i += 1;
    }
    Ok((here, parts[parts.len() - 1].to_string()))
}

/// Sets `path` to `value` in a TOML document (a key the table lacks is added); the error says
/// which part of the path names nothing.
pub fn set(doc: &mut toml::Table, path: &str, value: toml::Value) -> Result<(), String> {
    let (table, key) = parent(doc, path)?;
    table.insert(key, value);
    Ok(())
}

/// The value at `path` in a TOML document; `None` where the scene leaves it to its default.
pub fn get(doc: &toml::Table, path: &str) -> Result<Option<toml::Value>, String> {
    // `parent` walks mutably; a copy keeps the caller's document untouched.
    let mut doc = doc.clone();
    let (table, key) = parent(&mut doc, path)?;
    Ok(table.get(&key).cloned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keys, named entries and numbered entries are found; a missing table or entry is named.
    #[test]
    fn paths_name_keys_and_entries() {
        let mut doc: toml::Table = toml::from_str("[[material]]\nname = \"sand\"\nmu_s = 0.5\n[[stage]]\nduration = 1.0\n").unwrap();
        set(&mut doc, "material.sand.mu_s", toml::Value::Float(0.3)).unwrap();
        set(&mut doc, "stage.0.duration", toml::Value::Float(2.0)).unwrap();
        assert_eq!(get(&doc, "material.0.mu_s").unwrap(), Some(toml::Value::Float(0.3)));
        assert_eq!(get(&doc, "stage.0.duration").unwrap(), Some(toml::Value::Float(2.0)));
        assert_eq!(get(&doc, "material.sand.mu_r").unwrap(), None);
        assert_eq!(get(&doc, "simulation.dt").unwrap_err(), "the scene has no `simulation`");
        assert_eq!(set(&mut doc, "material.glass.mu_s", toml::Value::Float(0.1)).unwrap_err(), "`material` has no entry named or numbered `glass`");
    }
}
