//! The user's documentation against the code: every relative link in the README and `docs/`
//! resolves (file and heading), and every key the scene parser accepts is in the scene
//! reference, under its table's heading.

mod common;

use std::collections::BTreeSet;
use std::path::PathBuf;

use grains::scene::schema::SceneFile;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every Markdown file a reader is sent to: the README and everything under `docs/`.
fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    files.extend(common::files_below(&root().join("docs"), "md"));
    files
}

/// The text outside fenced code blocks, where `](...)` is a link.
fn prose(text: &str) -> String {
    let mut fenced = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The targets of the inline links `[text](target)` and images `![alt](target)`.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        match after.find(')') {
            Some(end) => {
                targets.push(after[..end].trim().to_string());
                rest = &after[end..];
            }
            None => break,
        }
    }
    targets
}

/// A heading's anchor as GitHub writes it: lower case, spaces to hyphens, punctuation dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(text: &str) -> BTreeSet<String> {
    prose(text)
        .lines()
        .filter_map(|l| l.strip_prefix('#'))
        .map(|l| anchor(l.trim_start_matches('#')))
        .collect()
}

#[test]
fn every_relative_link_in_the_readme_and_docs_resolves() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).unwrap();
        for target in link_targets(&prose(&text)) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, fragment) = match target.split_once('#') {
                Some((p, f)) => (p, Some(f)),
                None => (target.as_str(), None),
            };
            let resolved = if path.is_empty() { file.clone() } else { file.parent().unwrap().join(path) };
            let shown = file.strip_prefix(root()).unwrap().display().to_string();
            if !resolved.exists() {
                broken.push(format!("{shown}: ({target}): no such file"));
                continue;
            }
            if let Some(fragment) = fragment {
                let heading_file = if resolved.is_dir() { resolved.join("README.md") } else { resolved };
                let headings = anchors(&std::fs::read_to_string(&heading_file).unwrap_or_default());
                if !headings.contains(fragment) {
                    broken.push(format!("{shown}: ({target}): no heading with anchor #{fragment}"));
                }
            }
        }
    }
    assert!(checked > 20, "only {checked} relative links found: is the scan reading the files?");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// The keys serde accepts in one table, read from its own refusal of an unknown key: a table
/// holding `zzz_probe` is refused with "unknown field `zzz_probe`, expected one of `a`, `b`".
fn accepted_keys(toml_with_probe: &str) -> Vec<String> {
    let err = match toml::from_str::<SceneFile>(toml_with_probe) {
        Ok(_) => panic!("a scene with the key zzz_probe parsed:\n{toml_with_probe}"),
        Err(e) => e.to_string(),
    };
    let list = err
        .split("unknown field `zzz_probe`, expected")
        .nth(1)
        .unwrap_or_else(|| panic!("the probe was refused for another reason:\n{toml_with_probe}\n{err}"));
    list.lines().next().unwrap().split('`').skip(1).step_by(2).map(str::to_string).collect()
}

/// The scene reference's section whose heading names `table`.
fn section<'a>(reference: &'a str, table: &str) -> &'a str {
    let start = reference
        .match_indices("\n## ")
        .map(|(i, _)| i + 1)
        .find(|&i| reference[i..].lines().next().unwrap().contains(table))
        .unwrap_or_else(|| panic!("docs/scene-reference.md has no section headed {table}"));
    let end = reference[start + 3..].find("\n## ").map_or(reference.len(), |e| start + 3 + e);
    &reference[start..end]
}

fn mentions(text: &str, key: &str) -> bool {
    text.match_indices(key).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + key.len()..].chars().next();
        let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !word(before) && !word(after)
    })
}

#[test]
fn every_scene_key_the_parser_accepts_is_in_the_scene_reference() {
    let reference = std::fs::read_to_string(root().join("docs/scene-reference.md")).unwrap();
    let probes: &[(&str, &str)] = &[
        ("Top level", "zzz_probe = 1"),
        ("`[[material]]`", "[[material]]\nzzz_probe = 1"),
        ("`[[pair]]`", "[[pair]]\nzzz_probe = 1"),
        ("`[[grain]]`", "[[grain]]\nzzz_probe = 1"),
        ("`[[read]]`", "[[read]]\nzzz_probe = 1"),
        ("`[[generate]]`", "[[generate]]\nzzz_probe = 1"),
        ("`[[generate]]`", "[[generate]]\ndiameter = { zzz_probe = 1 }"),
        ("`[[generate]]`", "[[generate]]\nregion = { shape = \"box\", zzz_probe = 1 }"),
        ("`[[generate]]`", "[[generate]]\nregion = { shape = \"cylinder\", zzz_probe = 1 }"),
        ("`[[wall]]`", "[[wall]]\ntype = \"plane\"\nzzz_probe = 1"),
        ("`[[wall]]`", "[[wall]]\ntype = \"box\"\nzzz_probe = 1"),
        ("`[[wall]]`", "[[wall]]\ntype = \"cylinder\"\nzzz_probe = 1"),
        ("`[[wall]]`", "[[wall]]\ntype = \"servo_box\"\nzzz_probe = 1"),
        ("`[[wall]]`", "[[wall]]\ntype = \"piston\"\nzzz_probe = 1"),
        ("`[[inlet]]`", "[[inlet]]\nzzz_probe = 1"),
        ("`[[inlet]]`", "[[inlet]]\nregion = { shape = \"box\", zzz_probe = 1 }"),
        ("`[[outlet]]`", "[[outlet]]\nzzz_probe = 1"),
        ("`[periodic]`", "[periodic]\nzzz_probe = 1"),
        ("`[model]`", "[model]\nzzz_probe = 1"),
        ("`[simulation]`", "[simulation]\nzzz_probe = 1"),
        ("`[contact_dynamics]`", "[contact_dynamics]\nzzz_probe = 1"),
        ("`[[stage]]`", "[[stage]]\nzzz_probe = 1"),
        ("`[output]`", "[output]\nzzz_probe = 1"),
    ];
    let tables = ["material", "pair", "grain", "read", "generate", "wall", "inlet", "outlet", "periodic", "model", "simulation", "stage", "output", "contact_dynamics"];
    let mut missing = Vec::new();
    let mut count = 0;
    for (heading, probe) in probes {
        let text = section(&reference, heading);
        for key in accepted_keys(probe) {
            if *heading == "Top level" && tables.contains(&key.as_str()) {
                assert!(reference.contains(&format!("`[{key}]`")) || reference.contains(&format!("`[[{key}]]`")), "no section for [{key}]");
                continue;
            }
            count += 1;
            if !mentions(text, &key) {
                missing.push(format!("{heading}: {key}"));
            }
        }
    }
    println!("{count} keys probed");
    assert!(count > 60, "only {count} keys probed: has the parser's error format changed?");
    assert!(missing.is_empty(), "keys the parser accepts that docs/scene-reference.md does not list under their table:\n{}", missing.join("\n"));
}

#[test]
fn the_link_and_key_readers_see_what_they_must() {
    // The two tests above pass by finding nothing wrong; make sure their readers can fail.
    assert_eq!(link_targets("see [a](b.md) and ![c](d/e.png#f) and [x](http://y)"), ["b.md", "d/e.png#f", "http://y"]);
    assert!(link_targets(&prose("```\n[a](b)\n```\n")).is_empty());
    assert_eq!(anchor("Contact dynamics beside molecular dynamics (S_1, S_2)"), "contact-dynamics-beside-molecular-dynamics-s_1-s_2");
    assert!(mentions("min = [0], max = 1", "max") && !mentions("max_speed = 1", "max"));
    assert!(accepted_keys("[output]\nzzz_probe = 1").contains(&"vtk".to_string()));
}
