//! The layers of `src/`, checked file by file: every library file imports only files of
//! its own layer or below, the file graph has no cycle, file formats and pictures stay out
//! of the algorithms, and no two files share a basename.
//!
//! The layers, lowest first (`docs/architecture.md`):
//! `core < model < kinematics, dynamics < robot < collision, planning, motion, sim,
//! workspace, machines < io < scenarios < studies`. The binary (`src/main.rs`,
//! `src/cli/`) sits on top and is not part of the graph; `lib.rs` only re-exports.
//!
//! How an edge is found: every path in a file's code (comments and strings removed) that
//! starts with `crate::`, `super::`, `self::` or the name of one of the file's child
//! modules, in `use` trees and in expressions, is resolved to the file that defines the
//! item. A path through a module that re-exports the item (`pub use`, also `*`) is
//! followed to the file the item comes from, so a `mod.rs` that re-exports its children
//! is not counted as their dependency.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module path (`a::b`) → file (relative to `src/`), for the library's files.
type Files = BTreeMap<String, String>;
/// File → (imported file → the paths that import it).
type Graph = BTreeMap<String, BTreeMap<String, BTreeSet<String>>>;

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a file relative to `src/` (`a/b/mod.rs` and `a/b.rs` → `a::b`).
fn module_of(rel: &str) -> String {
    let s = rel.trim_end_matches(".rs");
    let s = s.strip_suffix("/mod").unwrap_or(s);
    if s == "lib" {
        return String::new();
    }
    s.replace('/', "::")
}

/// The library's files (no binary, no `lib.rs`) by module path, and their text.
fn library() -> (Files, BTreeMap<String, String>) {
    let mut all = Vec::new();
    rust_files(&src(), &mut all);
    let (mut files, mut texts) = (Files::new(), BTreeMap::new());
    for f in all {
        let rel = f
            .strip_prefix(src())
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel == "main.rs" || rel == "lib.rs" || rel.starts_with("cli/") {
            continue;
        }
        texts.insert(rel.clone(), strip(&std::fs::read_to_string(&f).unwrap()));
        files.insert(module_of(&rel), rel);
    }
    (files, texts)
}

/// `code` with comments, string literals and character literals blanked out (line
/// breaks kept), so that only code is searched for paths.
fn strip(code: &str) -> String {
    let c: Vec<char> = code.chars().collect();
    let mut out = String::with_capacity(code.len());
    let mut i = 0;
    while i < c.len() {
        let next = c.get(i + 1).copied().unwrap_or(' ');
        if c[i] == '/' && next == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && next == '*' {
            i += 2;
            while i + 1 < c.len() && !(c[i] == '*' && c[i + 1] == '/') {
                i += 1;
            }
            i += 2;
        } else if c[i] == 'r' && (next == '"' || next == '#') && !ident_char(&c, i.wrapping_sub(1))
        {
            let hashes = c[i + 1..].iter().take_while(|&&x| x == '#').count();
            if c.get(i + 1 + hashes) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            i += hashes + 2;
            while i < c.len() && !(c[i] == '"' && c[i + 1..].iter().take(hashes).all(|&x| x == '#'))
            {
                i += 1;
            }
            i += hashes + 1;
            out.push_str("\"\"");
        } else if c[i] == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    i += 1;
                }
                if c.get(i) == Some(&'\n') {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c[i] == '\'' && (next == '\\' || c.get(i + 2) == Some(&'\'')) {
            i += 1;
            while i < c.len() && c[i] != '\'' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("' '");
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

fn ident_char(c: &[char], i: usize) -> bool {
    c.get(i).is_some_and(|x| x.is_alphanumeric() || *x == '_')
}

/// The paths of every `use` tree in `code` (groups expanded; `as` renames kept as
/// `(path, name)`; `*` as the last segment).
fn use_trees(code: &str) -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = find_word(rest, "use") {
        let tail = &rest[i + 3..];
        let end = tail.find(';').unwrap_or(tail.len());
        expand(tail[..end].trim(), &mut Vec::new(), &mut out);
        rest = &tail[end..];
    }
    out
}

fn find_word(s: &str, w: &str) -> Option<usize> {
    let b = s.as_bytes();
    let mut from = 0;
    while let Some(k) = s[from..].find(w) {
        let i = from + k;
        let before = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        let after = b.get(i + w.len()).is_some_and(|x| x.is_ascii_whitespace());
        if before && after {
            return Some(i);
        }
        from = i + w.len();
    }
    None
}

fn expand(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    let tree = tree.trim().trim_start_matches("::");
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = tree[..open]
            .split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let n = prefix.len();
        prefix.extend(head);
        let mut depth = 0;
        let mut start = 0;
        for (k, ch) in inner.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&inner[start..k], prefix, out);
                    start = k + 1;
                }
                _ => {}
            }
        }
        expand(&inner[start..], prefix, out);
        prefix.truncate(n);
        return;
    }
    let (path, alias) = match tree.split_once(" as ") {
        Some((p, a)) => (p.trim(), a.trim().to_string()),
        None => (tree, String::new()),
    };
    if path.is_empty() {
        return;
    }
    let mut full = prefix.clone();
    full.extend(path.split("::").map(|s| s.trim().to_string()));
    if full.last().is_some_and(|s| s == "self") {
        full.pop();
    }
    let name = if alias.is_empty() {
        full.last().cloned().unwrap_or_default()
    } else {
        alias
    };
    out.push((full, name));
}

/// Every `a::b::c` path in expression position of `code` (outside `use` trees).
fn expression_paths(code: &str) -> Vec<Vec<String>> {
    let c: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if (c[i].is_alphabetic() || c[i] == '_') && !ident_char(&c, i.wrapping_sub(1)) {
            let mut segs = Vec::new();
            let mut j = i;
            loop {
                let s = j;
                while ident_char(&c, j) {
                    j += 1;
                }
                segs.push(c[s..j].iter().collect::<String>());
                if c.get(j) == Some(&':') && c.get(j + 1) == Some(&':') && ident_char(&c, j + 2) {
                    j += 2;
                } else {
                    break;
                }
            }
            if segs.len() > 1 && c.get(i.wrapping_sub(1)) != Some(&':') {
                out.push(segs);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// Turns a path written in module `m` into an absolute module path, or `None` for paths
/// into other crates, local names and `Self`.
fn absolute(files: &Files, m: &str, path: &[String]) -> Option<Vec<String>> {
    let here: Vec<String> = m
        .split("::")
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    let first = path.first()?.as_str();
    let mut abs = match first {
        "crate" => Vec::new(),
        "self" => here.clone(),
        "super" => here[..here.len().saturating_sub(1)].to_vec(),
        _ => {
            let child = [here.clone(), vec![first.to_string()]].concat().join("::");
            if !files.contains_key(&child) {
                return None;
            }
            return Some([here, path.to_vec()].concat());
        }
    };
    for s in &path[1..] {
        if s == "super" {
            abs.pop();
        } else {
            abs.push(s.clone());
        }
    }
    Some(abs)
}

/// Whether `code` defines an item named `name`.
fn defines(code: &str, name: &str) -> bool {
    [
        "fn", "struct", "enum", "trait", "type", "const", "static", "mod", "union",
    ]
    .iter()
    .any(|kw| {
        let pat = format!("{kw} {name}");
        code.match_indices(&pat).any(|(i, _)| {
            let before = code[..i]
                .chars()
                .last()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
            let after = code[i + pat.len()..]
                .chars()
                .next()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
            before && after
        })
    })
}

/// The file that defines the item `path` names, following re-exports.
fn resolve(
    files: &Files,
    texts: &BTreeMap<String, String>,
    path: &[String],
    depth: usize,
) -> Option<String> {
    let mut m: Vec<String> = Vec::new();
    for seg in path {
        let cand = [m.clone(), vec![seg.clone()]].concat();
        if files.contains_key(&cand.join("::")) {
            m = cand;
            continue;
        }
        let file = files.get(&m.join("::"))?;
        if depth < 8 {
            if let Some(f) = reexport(files, texts, &m.join("::"), seg, depth) {
                return Some(f);
            }
        }
        return Some(file.clone());
    }
    files.get(&m.join("::")).cloned()
}

/// Where module `m` gets a `name` it re-exports (`pub use`), if it does.
fn reexport(
    files: &Files,
    texts: &BTreeMap<String, String>,
    m: &str,
    name: &str,
    depth: usize,
) -> Option<String> {
    let text = &texts[&files[m]];
    if defines(text, name) {
        return None;
    }
    for (path, alias) in use_trees(text) {
        // Imports of other crates (`std`, `serde`, …) say nothing about this name.
        let Some(abs) = absolute(files, m, &path) else {
            continue;
        };
        if alias == name {
            return resolve(files, texts, &abs, depth + 1);
        }
        if alias == "*" {
            let mut p = abs.clone();
            p.pop();
            p.push(name.to_string());
            match resolve(files, texts, &p, depth + 1) {
                Some(f) if defines(&texts[&f], name) => return Some(f),
                _ => {}
            }
        }
    }
    None
}

/// The file graph of the library.
fn file_graph(files: &Files, texts: &BTreeMap<String, String>) -> Graph {
    let mut g = Graph::new();
    for (m, f) in files {
        let node = g.entry(f.clone()).or_default();
        // The unit tests at the end of a file are its child module `tests`.
        let code = &texts[f];
        let split = code.find("mod tests {").unwrap_or(code.len());
        let tests_mod = format!("{m}::tests");
        let mut paths: Vec<(&str, Vec<String>)> = Vec::new();
        for (part, module) in [
            (&code[..split], m.as_str()),
            (&code[split..], tests_mod.as_str()),
        ] {
            paths.extend(use_trees(part).into_iter().map(|(p, _)| (module, p)));
            paths.extend(expression_paths(part).into_iter().map(|p| (module, p)));
        }
        for (module, p) in paths {
            let p: Vec<String> = p.into_iter().filter(|s| s != "*").collect();
            let Some(abs) = absolute(files, module, &p) else {
                continue;
            };
            if let Some(t) = resolve(files, texts, &abs, 0) {
                if &t != f {
                    node.entry(t).or_default().insert(abs.join("::"));
                }
            }
        }
    }
    g
}

/// The layer of a file (relative to `src/`): 0 = `core` … 7 = `studies`.
fn layer(rel: &str) -> usize {
    let top = rel.split('/').next().unwrap().trim_end_matches(".rs");
    match top {
        "core" => 0,
        "model" => 1,
        "kinematics" | "dynamics" => 2,
        "robot" => 3,
        "collision" | "planning" | "motion" | "sim" | "workspace" | "machines" => 4,
        "io" => 5,
        "scenarios" => 6,
        "studies" => 7,
        other => panic!("src/{rel}: top-level module '{other}' has no layer in tests/layers.rs"),
    }
}

/// Strongly connected components of more than one file (Tarjan).
fn cycles(graph: &Graph) -> Vec<Vec<String>> {
    struct St<'g> {
        g: &'g Graph,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn visit(s: &mut St, v: &str) {
        let i = s.index.len();
        s.index.insert(v.into(), i);
        s.low.insert(v.into(), i);
        s.stack.push(v.into());
        s.on.insert(v.into());
        let next: Vec<String> =
            s.g.get(v)
                .map(|m| m.keys().cloned().collect())
                .unwrap_or_default();
        for w in next {
            if !s.index.contains_key(&w) {
                visit(s, &w);
                let lw = s.low[&w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(&w) {
                let iw = s.index[&w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on.remove(&w);
                let done = w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = St {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

#[test]
fn no_file_imports_a_file_of_a_higher_layer() {
    let (files, texts) = library();
    assert!(files.len() > 200, "read only {} files", files.len());
    let g = file_graph(&files, &texts);
    let mut bad = String::new();
    for (a, deps) in &g {
        for (b, paths) in deps {
            if layer(b) > layer(a) {
                bad += &format!(
                    "  {a} (layer {}) -> {b} (layer {}) via {paths:?}\n",
                    layer(a),
                    layer(b)
                );
            }
        }
    }
    assert!(bad.is_empty(), "imports that go up a layer:\n{bad}");
}

/// No file-level import cycle anywhere in `src/`: a cycle names every import along it.
#[test]
fn the_file_graph_has_no_cycle() {
    let (files, texts) = library();
    let g = file_graph(&files, &texts);
    let mut report = String::new();
    for comp in cycles(&g) {
        report += &format!("cycle among {comp:?}:\n");
        for a in &comp {
            for (b, paths) in &g[a] {
                if comp.contains(b) {
                    report += &format!("  {a} -> {b} via {paths:?}\n");
                }
            }
        }
    }
    assert!(report.is_empty(), "{report}");
}

#[test]
fn file_formats_and_pictures_stay_out_of_the_algorithms() {
    let (files, texts) = library();
    let mut bad = Vec::new();
    for f in files.values() {
        let code = &texts[f];
        let l = layer(f);
        let names_crate = |c: &str| {
            code.contains(&format!("{c}::"))
                || find_word(code, c).is_some_and(|i| code[..i].ends_with("use "))
        };
        if l <= 5 && !f.starts_with("model/parse/") && names_crate("toml") {
            bad.push(format!("{f} names toml"));
        }
        for c in ["plotters", "png"] {
            if l <= 4 && names_crate(c) {
                bad.push(format!("{f} names {c}"));
            }
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn no_two_files_share_a_basename() {
    let mut all = Vec::new();
    rust_files(&src(), &mut all);
    let mut seen: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for f in all {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        if name != "mod.rs" {
            seen.entry(name).or_default().push(f.display().to_string());
        }
    }
    seen.retain(|_, v| v.len() > 1);
    assert!(seen.is_empty(), "{seen:#?}");
}

#[test]
fn the_checker_finds_a_planted_cycle_an_upward_import_and_a_reexport() {
    let mut files = Files::new();
    let mut texts = BTreeMap::new();
    for (m, f, code) in [
        // The re-export follows an import of another crate: still followed.
        (
            "core",
            "core/mod.rs",
            "use std::fmt;\npub mod a;\npub use a::Thing;\n",
        ),
        (
            "core::a",
            "core/a.rs",
            "pub struct Thing;\nfn f() { crate::scenarios::run(); }\n",
        ),
        (
            "scenarios",
            "scenarios/mod.rs",
            "use crate::core::Thing;\npub fn run() {}\n",
        ),
    ] {
        files.insert(m.to_string(), f.to_string());
        texts.insert(f.to_string(), strip(code));
    }
    let g = file_graph(&files, &texts);
    assert!(g["scenarios/mod.rs"].contains_key("core/a.rs"), "{g:?}");
    assert!(!g["scenarios/mod.rs"].contains_key("core/mod.rs"), "{g:?}");
    assert!(g["core/a.rs"].contains_key("scenarios/mod.rs"));
    assert_eq!(cycles(&g), vec![vec!["core/a.rs", "scenarios/mod.rs"]]);
    assert!(layer("core/a.rs") < layer("scenarios/mod.rs"));
    assert_eq!(
        strip("let s = \"crate::x\"; // crate::y\nf('{');"),
        "let s = \"\"; \nf(' ');"
    );
}

#[test]
fn no_two_public_types_share_a_name() {
    // The ROS 2 message structs keep their ROS names beside the recording's own types.
    const ROS_NAMES: [&str; 2] = ["Header", "Transform"];
    let (files, texts) = library();
    let mut seen: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for f in files.values() {
        for line in texts[f].lines() {
            let t = line.trim_start();
            for kw in ["pub struct ", "pub enum ", "pub trait ", "pub type "] {
                if let Some(rest) = t.strip_prefix(kw) {
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    seen.entry(name).or_default().push(f.clone());
                }
            }
        }
    }
    seen.retain(|name, v| v.len() > 1 && !ROS_NAMES.contains(&name.as_str()));
    assert!(seen.is_empty(), "{seen:#?}");
    for name in ROS_NAMES {
        assert!(texts["io/record/ros2.rs"].contains(&format!("pub struct {name}")));
    }
}
