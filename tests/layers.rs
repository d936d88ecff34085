//! The crate's layering, read from its sources: the engines share `state` and do not lean on
//! one another's insides (the GPU engine and contact dynamics import nothing from the CPU
//! engine), the shared state imports no engine, the validated scene's plain data imports
//! nothing above it, and no two modules import each other, directly or around a loop.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Every `.rs` file under `src/`, with its path relative to `src/`.
fn sources() -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    common::files_below(&src, "rs")
        .into_iter()
        .map(|p| (p.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/"), std::fs::read_to_string(&p).unwrap()))
        .collect()
}

/// The code of a source file without its comments (line comments, doc comments included) and
/// without the insides of its string literals (an error message may name a path).
fn code(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let chars: Vec<char> = line.chars().collect();
        let mut in_string = false;
        let mut k = 0;
        while k < chars.len() {
            let c = chars[k];
            if !in_string && c == '/' && chars.get(k + 1) == Some(&'/') {
                break;
            }
            let char_literal = k > 0 && chars[k - 1] == '\'' && chars.get(k + 1) == Some(&'\'');
            if c == '\\' && in_string {
                k += 2;
                continue;
            }
            if c == '"' && !char_literal {
                in_string = !in_string;
            } else if !in_string {
                out.push(c);
            }
            k += 1;
        }
        out.push('\n');
    }
    out
}

/// The layer a file belongs to: its top-level module, except that the validated scene's plain
/// data (`scene/types.rs`) is a layer of its own beneath the scene's validation.
fn layer_of_file(path: &str) -> String {
    if path == "scene/types.rs" {
        return "scene::types".into();
    }
    let top = path.split('/').next().unwrap();
    top.trim_end_matches(".rs").to_string()
}

/// The layers a file's code names through `crate::` (or `grains::`, in the binary's modules).
fn layers_named(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for prefix in ["crate::", "grains::"] {
        for (at, _) in code.match_indices(prefix) {
            let rest = &code[at + prefix.len()..];
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if name.is_empty() {
                continue;
            }
            let after = &rest[name.len()..];
            if name == "scene" && after.starts_with("::types") {
                out.insert("scene::types".to_string());
            } else {
                out.insert(name);
            }
        }
    }
    out
}

/// The import graph between layers, and the files behind each edge.
fn graph() -> Graph {
    let mut g: Graph = BTreeMap::new();
    for (path, text) in sources() {
        let from = layer_of_file(&path);
        for to in layers_named(&code(&text)) {
            if to != from {
                g.entry(from.clone()).or_default().entry(to).or_default().push(path.clone());
            }
        }
        g.entry(from).or_default();
    }
    g
}

#[test]
fn the_gpu_engine_and_contact_dynamics_import_nothing_from_the_cpu_engine() {
    let mut found = Vec::new();
    for (path, text) in sources() {
        if (path.starts_with("gpu/") || path.starts_with("gpu.rs") || path.starts_with("cd/") || path.starts_with("state/"))
            && layers_named(&code(&text)).contains("cpu") {
                found.push(path);
            }
    }
    assert!(found.is_empty(), "files of gpu/, cd/ or state/ that import from cpu/: {found:?}");
}

#[test]
fn the_shared_state_imports_no_engine_and_the_scenes_data_nothing_above_it() {
    let g = graph();
    let state: BTreeSet<&String> = g["state"].keys().collect();
    for engine in ["cpu", "gpu", "cd", "protocol", "runner"] {
        assert!(!state.contains(&engine.to_string()), "state imports {engine}: {:?}", g["state"][engine]);
    }
    let types: BTreeSet<&str> = g["scene::types"].keys().map(String::as_str).collect();
    assert!(types.is_subset(&BTreeSet::from(["model", "real", "mesh"])), "scene/types.rs imports {types:?}");
    // The meshes a scene holds are geometry over the numbers alone.
    let mesh: BTreeSet<&str> = g["mesh"].keys().map(String::as_str).collect();
    assert!(mesh.is_subset(&BTreeSet::from(["real"])), "mesh/ imports {mesh:?}");
}

type Graph = BTreeMap<String, BTreeMap<String, Vec<String>>>;

/// The loops of a graph: its strongly connected components of more than one node (Tarjan).
fn loops(g: &Graph) -> Vec<Vec<String>> {
    struct Walk<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        loops: Vec<Vec<String>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            for w in self.g.get(v).into_iter().flat_map(|e| e.keys()) {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if self.stack.contains(&w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.loops.push(component);
                }
            }
        }
    }
    let mut walk = Walk { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), loops: Vec::new() };
    for v in g.keys() {
        if !walk.index.contains_key(v.as_str()) {
            walk.visit(v);
        }
    }
    walk.loops
}

#[test]
fn no_two_modules_import_each_other() {
    let g = &graph();
    assert!(g.len() > 20 && g["cpu"].contains_key("state"), "the graph was not read: {g:?}");
    let found = loops(g);
    let shown: Vec<String> = found
        .iter()
        .map(|c| {
            let edges: Vec<String> = c.iter().flat_map(|a| c.iter().filter_map(move |b| g[a].get(b).map(|files| format!("{a} -> {b} ({})", files.join(", "))))).collect();
            edges.join("; ")
        })
        .collect();
    assert!(found.is_empty(), "modules that import each other:\n{}", shown.join("\n"));
}

#[test]
fn the_readers_see_imports_and_loops() {
    assert_eq!(layers_named("use crate::scene::types::Wall; crate::cpu::X; grains::gpu::open()"), BTreeSet::from(["scene::types".to_string(), "cpu".into(), "gpu".into()]));
    assert!(layers_named(&code("// crate::cpu in a comment\n/// and crate::gpu in a doc")).is_empty());
    assert_eq!(layers_named(&code("bail!(\"see grains::runner \\\" here\"); crate::cd::X; '\"'; crate::gpu::Y")), BTreeSet::from(["cd".to_string(), "gpu".into()]));
    assert_eq!(layer_of_file("scene/types.rs"), "scene::types");
    assert_eq!(layer_of_file("cpu/ranks/mod.rs"), "cpu");
    let edge = |a: &str, b: &str| (a.to_string(), BTreeMap::from([(b.to_string(), vec![])]));
    let looped: Graph = BTreeMap::from([edge("a", "b"), edge("b", "c"), edge("c", "a"), edge("d", "a")]);
    assert_eq!(loops(&looped), vec![vec!["a".to_string(), "b".into(), "c".into()]]);
    assert!(loops(&BTreeMap::from([edge("a", "b"), edge("b", "c")])).is_empty());
}

#[test]
fn no_source_file_is_a_grab_bag() {
    // One job per file: past about 600 lines a file holds several, and a reader loses the
    // thread (split by job, as cpu/, scene/ and model/ are).
    const MOST_LINES: usize = 600;
    let long: Vec<String> = sources().into_iter().filter(|(_, text)| text.lines().count() > MOST_LINES).map(|(path, text)| format!("{path}: {} lines", text.lines().count())).collect();
    assert!(long.is_empty(), "files over {MOST_LINES} lines: {long:?}");
}
