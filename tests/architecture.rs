//! The layers of `src/` point one way, and no module depends on itself through
//! others (docs/architecture.md).
//!
//! Every `.rs` file under `src/` (but `src/bin/`) is a module; a folder's `mod.rs`
//! is the folder's module. The test reads each module's non-test code (comments,
//! string literals and `#[cfg(test)]` items removed), collects the paths it names
//! (`use crate::…`, `use super::…`, `use child::…`, and in code `crate::a::f`,
//! `super::a::f`, `child::f`),
//! resolves each to the module that defines it, and checks that
//! 1. an import either stays inside its top-level module or points to a lower layer
//!    (`LAYERS`), and
//! 2. the graph of modules has no cycle (a parent's `mod child;` declaration is not
//!    an import; a child that imports from its parent is).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules by layer, lowest first. A module may import from its own
/// top-level module and from any top-level module of a lower layer.
const LAYERS: &[&[&str]] = &[
    &["dim", "parallel"],
    &["material"],
    &["scene"],
    &["model"],
    &["physics", "output"],
    &["solver"],
    &["run"],
    &["analyses"],
];

fn layer_of(top: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&top))
}

/// Module path (`solver::implicit::newton`) → its non-test source.
type Modules = BTreeMap<String, String>;

/// Remove comments, the contents of string and char literals, and `#[cfg(test)]`
/// items (a `mod …;` declaration or a braced block).
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'r' && i + 1 < b.len() && (b[i + 1] == b'"' || b[i + 1] == b'#') {
            // Raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == b'#' {
                hashes += 1;
                j += 1;
            }
            if j < b.len() && b[j] == b'"' {
                let close: Vec<u8> = std::iter::once(b'"')
                    .chain(std::iter::repeat_n(b'#', hashes))
                    .collect();
                j += 1;
                while j < b.len() && !b[j..].starts_with(&close) {
                    j += 1;
                }
                out.push_str("\"\"");
                i = (j + close.len()).min(b.len());
            } else {
                out.push('r');
                i += 1;
            }
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            // A char literal ('a', '\n', '\''), not a lifetime.
            i += 1;
            while i < b.len() && b[i] != b'\'' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("' '");
        } else {
            let c = src[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    remove_test_items(&out)
}

fn remove_test_items(src: &str) -> String {
    let mut out = String::new();
    let mut rest = src;
    while let Some(k) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..k]);
        let after = &rest[k..];
        // The item ends at the first `;` before any `{`, or at the matching `}`.
        let semi = after.find(';');
        let brace = after.find('{');
        let end = match (semi, brace) {
            (Some(s), Some(b)) if s < b => s + 1,
            (Some(s), None) => s + 1,
            (_, Some(b)) => {
                let mut depth = 0;
                let mut end = after.len();
                for (j, c) in after[b..].char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = b + j + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                end
            }
            (None, None) => after.len(),
        };
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

/// Every module under `root` (src/), except the binaries, with its stripped source;
/// files declared only under `#[cfg(test)]` are left out.
fn read_modules(root: &Path) -> Modules {
    let mut files = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                if p.file_name().unwrap() != "bin" {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    let mut modules = Modules::new();
    for f in files {
        let rel: PathBuf = f.strip_prefix(root).unwrap().with_extension("");
        let mut parts: Vec<String> = rel
            .iter()
            .map(|s| s.to_string_lossy().into_owned())
            .collect();
        if parts.last().is_some_and(|l| l == "mod" || l == "lib") {
            parts.pop();
        }
        let name = parts.join("::");
        modules.insert(name, strip(&std::fs::read_to_string(&f).unwrap()));
    }
    // Modules that exist only in tests: `#[cfg(test)] mod x;` in the parent, so
    // the stripped parent does not declare them.
    let test_only: Vec<String> = modules
        .keys()
        .filter(|name| {
            let (parent, leaf) = name.rsplit_once("::").unwrap_or(("", name));
            !name.is_empty() && modules.get(parent).is_some_and(|src| !declares(src, leaf))
        })
        .cloned()
        .collect();
    for name in test_only {
        modules.remove(&name);
    }
    modules
}

/// Does this (stripped) source declare `mod leaf;`?
fn declares(src: &str, leaf: &str) -> bool {
    src.split(';').any(|s| {
        let words: Vec<&str> = s.split_whitespace().collect();
        words.len() >= 2 && words[words.len() - 2] == "mod" && words[words.len() - 1] == leaf
    })
}

/// Paths named by a `use` tree: `a::{b, c::{d, e}}` → a::b, a::c::d, a::c::e.
fn expand(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap().to_string()];
    };
    let prefix = &tree[..open];
    let inner = &tree[open + 1..tree.rfind('}').unwrap()];
    let mut parts = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (j, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..j]);
                start = j + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(|p| {
            expand(p).into_iter().map(move |q| {
                if q == "self" {
                    prefix.trim_end_matches("::").to_string()
                } else {
                    format!("{prefix}{q}")
                }
            })
        })
        .collect()
}

/// The paths a module names: its `use` trees and inline `crate::…` paths.
fn named_paths(src: &str) -> Vec<String> {
    let mut out = Vec::new();
    // The code without its `use` statements, for the paths written inline.
    let mut code = String::new();
    let mut last = 0;
    for (k, _) in src.match_indices("use ") {
        let before = src[..k].chars().last();
        if k < last || before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &src[k + 4..];
        if let Some(end) = rest.find(';') {
            out.extend(expand(&rest[..end]));
            code.push_str(&src[last..k]);
            last = k + 4 + end + 1;
        }
    }
    code.push_str(&src[last..]);
    out.extend(inline_paths(&code, "crate::"));
    out.extend(inline_paths(&code, "super::"));
    out
}

/// Paths in code that start with `start` (`crate::a::b::f`, `super::x::g`), not
/// inside a longer path.
fn inline_paths(src: &str, start: &str) -> Vec<String> {
    let b = src.as_bytes();
    src.match_indices(start)
        .filter(|&(k, _)| {
            k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_' || b[k - 1] == b':')
        })
        .map(|(k, _)| {
            let path: String = src[k..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            path.trim_end_matches(':').to_string()
        })
        .collect()
}

/// The child modules of `name` that its code names inline (`child::f(…)`).
fn children_named(name: &str, src: &str, modules: &Modules) -> Vec<String> {
    let prefix = if name.is_empty() {
        String::new()
    } else {
        format!("{name}::")
    };
    modules
        .keys()
        .filter_map(|m| m.strip_prefix(&prefix).filter(|c| !c.contains("::")))
        .filter(|c| !c.is_empty() && !inline_paths(src, &format!("{c}::")).is_empty())
        .map(|c| format!("{prefix}{c}"))
        .collect()
}

/// The module a path points into, seen from module `from`; None for other crates.
fn resolve(path: &str, from: &str, modules: &Modules) -> Option<String> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let mut base: Vec<String> = if from.is_empty() {
        Vec::new()
    } else {
        from.split("::").map(String::from).collect()
    };
    let mut rest = &segs[..];
    match segs.first() {
        Some(&"crate") => {
            base.clear();
            rest = &segs[1..];
        }
        Some(&"super") => {
            while rest.first() == Some(&"super") {
                base.pop();
                rest = &rest[1..];
            }
        }
        Some(&"self") => rest = &segs[1..],
        Some(first) => {
            // A child module of `from` (2018 paths); anything else is another crate.
            let child = if from.is_empty() {
                first.to_string()
            } else {
                format!("{from}::{first}")
            };
            if !modules.contains_key(&child) {
                return None;
            }
        }
        None => return None,
    }
    // The longest prefix that names a module.
    let mut best = base.join("::");
    let mut cur = base;
    let mut used = 0;
    for s in rest {
        cur.push(s.to_string());
        let name = cur.join("::");
        if modules.contains_key(&name) {
            best = name;
            used += 1;
        } else {
            break;
        }
    }
    // An item the module only re-exports (`pub use x::Item`, `pub use x::*`)
    // belongs to the module that defines it.
    match rest.get(used) {
        Some(item) => Some(origin(&best, item, modules, 0)),
        None => Some(best),
    }
}

/// The module that defines `item` as seen from module `m`: `m` itself, or, when
/// `m` re-exports it (`pub use x::Item`, `pub use x::*`), the module it comes from.
fn origin(m: &str, item: &str, modules: &Modules, depth: usize) -> String {
    let Some(src) = modules.get(m) else {
        return m.to_string();
    };
    if depth >= 8 || defines(src, item) {
        return m.to_string();
    }
    for path in pub_use_paths(src) {
        match path.strip_suffix("::*") {
            Some(glob) => {
                let Some(target) = resolve(glob, m, modules) else {
                    continue;
                };
                let found = origin(&target, item, modules, depth + 1);
                if modules.get(&found).is_some_and(|s| defines(s, item)) {
                    return found;
                }
            }
            None if path.rsplit("::").next() == Some(item) => {
                if let Some(found) = resolve(&path, m, modules) {
                    return found;
                }
            }
            None => {}
        }
    }
    m.to_string()
}

/// Does this (stripped) source define `item` (a type, trait, function, constant
/// or module of that name)?
fn defines(src: &str, item: &str) -> bool {
    [
        "struct", "enum", "fn", "type", "trait", "const", "static", "mod", "union",
    ]
    .iter()
    .any(|kw| {
        src.match_indices(&format!("{kw} {item}")).any(|(k, m)| {
            let after = src[k + m.len()..].chars().next();
            let before = src[..k].chars().last();
            !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
                && !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
        })
    })
}

/// The paths of a module's `pub use` and `pub(crate) use` trees.
fn pub_use_paths(src: &str) -> Vec<String> {
    let mut out = Vec::new();
    for start in ["pub use ", "pub(crate) use "] {
        for (k, _) in src.match_indices(start) {
            let rest = &src[k + start.len()..];
            if let Some(end) = rest.find(';') {
                out.extend(expand(&rest[..end]));
            }
        }
    }
    out
}

/// Module → the modules it imports (itself excluded).
fn graph(modules: &Modules) -> BTreeMap<String, BTreeSet<String>> {
    modules
        .iter()
        .map(|(name, src)| {
            let targets = named_paths(src)
                .iter()
                .filter_map(|p| resolve(p, name, modules))
                .chain(children_named(name, src, modules))
                .filter(|t| t != name && !t.is_empty())
                .collect();
            (name.clone(), targets)
        })
        .collect()
}

/// Imports that point up the layers (or into a top-level module of no layer).
fn upward(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let top = |m: &str| m.split("::").next().unwrap().to_string();
    let mut out = Vec::new();
    for (from, targets) in g {
        let tf = top(from);
        for to in targets {
            let tt = top(to);
            if tf == tt {
                continue;
            }
            match (layer_of(&tf), layer_of(&tt)) {
                (Some(a), Some(b)) if b < a => {}
                (a, b) => out.push(format!(
                    "{from} (layer {a:?}) imports {to} (layer {b:?}): not a lower layer"
                )),
            }
        }
    }
    out
}

/// Strongly connected components with more than one module (Tarjan).
fn cycles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on_stack.insert(v);
        let g = s.g;
        for w in g.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !g.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The graph with every module cut to its first `depth` path segments (a folder
/// seen as one module), without the edges inside one such group.
fn collapsed(
    g: &BTreeMap<String, BTreeSet<String>>,
    depth: usize,
) -> BTreeMap<String, BTreeSet<String>> {
    let cut = |m: &str| m.split("::").take(depth).collect::<Vec<_>>().join("::");
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (from, targets) in g {
        let f = cut(from);
        let entry = out.entry(f.clone()).or_default();
        entry.extend(targets.iter().map(|t| cut(t)).filter(|t| *t != f));
    }
    out
}

/// Cycles among modules, and among folders seen as one module at every depth.
fn all_cycles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    let depth = g.keys().map(|m| m.split("::").count()).max().unwrap_or(1);
    let mut out = cycles(g);
    for d in 1..depth {
        for c in cycles(&collapsed(g, d)) {
            if !out.contains(&c) {
                out.push(c);
            }
        }
    }
    out
}

fn src_graph() -> BTreeMap<String, BTreeSet<String>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    graph(&read_modules(&root))
}

#[test]
fn every_top_level_module_has_a_layer() {
    let g = src_graph();
    let missing: BTreeSet<&str> = g
        .keys()
        .map(|m| m.split("::").next().unwrap())
        .filter(|t| !t.is_empty() && layer_of(t).is_none())
        .collect();
    assert!(missing.is_empty(), "modules without a layer: {missing:?}");
}

#[test]
fn imports_point_down_the_layers() {
    let bad = upward(&src_graph());
    assert!(
        bad.is_empty(),
        "{} upward imports:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn no_module_depends_on_itself() {
    let found = all_cycles(&src_graph());
    let text: Vec<String> = found.iter().map(|c| c.join(" ↔ ")).collect();
    assert!(
        found.is_empty(),
        "{} cycles:\n{}",
        found.len(),
        text.join("\n")
    );
}

/// The checker itself finds an upward import and a cycle in a small made-up tree,
/// sees through comments, strings and test modules, and resolves grouped,
/// relative and inline paths.
#[test]
fn the_checker_finds_what_it_should() {
    let mut m = Modules::new();
    let add = |m: &mut Modules, name: &str, src: &str| {
        m.insert(name.to_string(), strip(src));
    };
    add(
        &mut m,
        "",
        "pub mod model; pub mod physics; pub mod solver;",
    );
    add(
        &mut m,
        "model",
        "pub mod grid;\nuse crate::physics::shape::Stencils; // up!\nfn f() { grid::g(); }",
    );
    add(
        &mut m,
        "model::grid",
        "// use crate::solver::x;\nconst S: &str = \"crate::solver\";",
    );
    add(&mut m, "physics", "pub mod shape;");
    add(
        &mut m,
        "physics::shape",
        "use crate::{model::grid::Grid, dim};\n#[cfg(test)]\nmod tests { use crate::solver::a; }",
    );
    add(&mut m, "solver", "pub mod a; pub mod b; use a::X;");
    add(&mut m, "solver::a", "fn f() { crate::solver::b::g(); }");
    add(&mut m, "solver::b", "use super::a::Y;");
    add(&mut m, "solver::c", "pub mod d;\npub use d::*;");
    add(&mut m, "solver::f", "use crate::solver::c::Thing;");
    add(
        &mut m,
        "solver::c::d",
        "use crate::solver::e::Z;\npub struct Thing;",
    );
    add(&mut m, "solver::e", "fn h() { super::c::w(); }");
    let g = graph(&m);
    assert_eq!(
        g["physics::shape"],
        BTreeSet::from(["model::grid".to_string()])
    );
    assert!(g["model::grid"].is_empty(), "{:?}", g["model::grid"]);
    assert_eq!(g["solver"], BTreeSet::from(["solver::a".to_string()]));
    assert!(g["model"].contains("model::grid"), "{:?}", g["model"]);
    // Through a re-export, to the module that defines the item.
    assert_eq!(g["solver::f"], BTreeSet::from(["solver::c::d".to_string()]));
    assert_eq!(g["solver::e"], BTreeSet::from(["solver::c".to_string()]));
    let bad = upward(&g);
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(
        bad[0].starts_with("model (layer") && bad[0].contains("imports physics::shape"),
        "{bad:?}"
    );
    let found = all_cycles(&g);
    assert_eq!(
        found,
        vec![
            vec!["solver::a".to_string(), "solver::b".to_string()],
            // c re-exports d, d imports e, e calls into c.
            vec![
                "solver::c".to_string(),
                "solver::c::d".to_string(),
                "solver::e".to_string(),
            ],
            // Seen with folders as one module: the upward import closes a cycle.
            vec!["model".to_string(), "physics".to_string()],
            vec!["solver::c".to_string(), "solver::e".to_string()],
        ]
    );
}
