//! The project names the two papers it implements by their authors (Oquendo, Muñoz & Lizcano;
//! Richefeu, El Youssoufi, Azéma & Radjai 2009), never by the numbers of the files they came in
//! as: every tracked source, scene, script and document is read for those numbers.

use std::path::Path;

/// The files git tracks, relative to the repository's root; outside a git checkout, every
/// file below it but the build's and git's own.
fn tracked() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    if let Ok(out) = std::process::Command::new("git").arg("-C").arg(root).arg("ls-files").output()
        && out.status.success() {
            return String::from_utf8(out.stdout).expect("UTF-8 paths").lines().map(str::to_string).collect();
        }
    let mut files = Vec::new();
    let mut dirs = vec![root.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).expect("a readable tree").flatten() {
            let path = entry.path();
            let name = entry.file_name();
            if path.is_dir() {
                if name != "target" && name != ".git" && name != "out" {
                    dirs.push(path);
                }
            } else {
                files.push(path.strip_prefix(root).expect("below the root").to_string_lossy().into_owned());
            }
        }
    }
    files
}

#[test]
fn the_papers_are_named_by_their_authors() {
    // The word and the numbers are joined here so that this file does not match itself.
    let bad: Vec<String> = ["000", "001"].iter().flat_map(|n| [format!("{} {n}", "seed"), format!("{}{n}", "seed"), format!("{}_{n}", "seed"), format!("{}-{n}", "seed")]).collect();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    for file in tracked() {
        // Binary files (pictures, recordings) are not read.
        let Ok(text) = std::fs::read_to_string(root.join(&file)) else { continue };
        let lower = text.to_lowercase();
        for (k, line) in lower.lines().enumerate() {
            if bad.iter().any(|b| line.contains(b.as_str())) {
                found.push(format!("{file}:{}", k + 1));
            }
        }
        if bad.iter().any(|b| file.to_lowercase().contains(b.as_str())) {
            found.push(file.clone());
        }
    }
    assert!(found.is_empty(), "name the papers by their authors (Oquendo et al.; Richefeu et al. (2009)) at: {}", found.join(", "));
}
