//! The module graph of `src/` has no cycle: lower layers never import higher ones.
//!
//! Reads every library source file as text, records an edge `a → b` for each
//! `crate::b` path in top-level module `a` (comments skipped; `use crate::{b, c}` lists
//! included), and fails naming the edges of any strongly connected component. The binary
//! (`src/main.rs`, `src/cli/`) sits on top and is not part of the graph.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Graph = BTreeMap<String, BTreeMap<String, BTreeSet<String>>>;

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

/// The identifiers following `crate::` in `code`, including the names of a
/// `crate::{a, b::c}` group.
fn crate_refs(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for part in group[..end].split(',') {
                let name = ident(part.trim());
                if !name.is_empty() {
                    out.push(name);
                }
            }
        } else {
            out.push(ident(rest));
        }
    }
    out
}

/// `module → (imported module → files)` for the library's top-level modules.
fn module_graph() -> Graph {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut graph = Graph::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let top = top.trim_end_matches(".rs").to_string();
        if ["main", "lib", "cli", "bin"].contains(&top.as_str()) {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        let code: String = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let node = graph.entry(top.clone()).or_default();
        for r in crate_refs(&code) {
            if r != top && r != "self" && !r.is_empty() {
                node.entry(r).or_default().insert(rel.display().to_string());
            }
        }
    }
    graph
}

/// Strongly connected components with more than one module (Tarjan, iterative enough
/// for a few dozen modules).
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
fn the_crate_module_graph_has_no_cycle() {
    let graph = module_graph();
    assert!(graph.len() > 15, "read only {} modules", graph.len());
    let found = cycles(&graph);
    let mut report = String::new();
    for comp in &found {
        report += &format!("cycle among {comp:?}:\n");
        for a in comp {
            for (b, files) in &graph[a] {
                if comp.contains(b) {
                    report += &format!("  {a} -> {b} ({files:?})\n");
                }
            }
        }
    }
    assert!(found.is_empty(), "{report}");
}

#[test]
fn the_cycle_finder_finds_a_planted_cycle() {
    let mut g = Graph::new();
    for (a, b) in [("model", "scenario"), ("scenario", "arm"), ("arm", "model")] {
        g.entry(a.into()).or_default().entry(b.into()).or_default();
    }
    g.entry("spatial".into()).or_default();
    assert_eq!(cycles(&g), vec![vec!["arm", "model", "scenario"]]);
    assert_eq!(
        crate_refs(
            "use crate::{diag::line_at, model};\nlet x = crate::core::spatial::Vec3::zeros();"
        ),
        vec!["diag", "model", "spatial"]
    );
}

#[test]
fn the_leaf_modules_import_nothing_from_the_crate() {
    let graph = module_graph();
    for leaf in ["diag", "report", "linalg", "spatial"] {
        let deps: Vec<_> = graph
            .get(leaf)
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default();
        assert!(
            deps.iter().all(|d| d == "fastmath"),
            "{leaf} imports {deps:?}"
        );
    }
}
