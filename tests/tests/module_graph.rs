//! No import circles between the modules of a crate.
//!
//! An import circle (module `a` uses `b`, and `b`, directly or through others, uses `a`) makes a crate
//! hard to follow: no module of the circle can be read, or changed, before the others. For every crate of
//! the workspace (`<member>/src` of each member the workspace's `Cargo.toml` names) this builds the
//! module-level import graph and fails on each strongly connected component of more than one module,
//! listing, for each module of the circle, the modules of the circle that it uses, so that a developer sees
//! what to untangle.
//!
//! The graph, read from the sources with a few regular expressions (no compiler):
//! - a module per `.rs` file under `src/`, named by its path; `lib.rs`, `main.rs` and `mod.rs` name their
//!   folder's module (`lib.rs` is the crate root; a `main.rs` beside it is the binary's own root, which uses
//!   the library by its name, so it is not part of the library's graph);
//! - code from the first `#[cfg(test)]` on, and `//` comments, are not read;
//! - an edge to the module that a `crate::a::b` path, a `use crate::{..}` group, a `super::` path, a
//!   `use super::{..}` group or a `use child::` naming a child module leads to;
//! - `pub use`, `pub(crate) use` and `pub(super) use` are re-exports, not dependencies: a crate root's
//!   facade re-exports every module and uses none of them. They do lead a path on: `crate::Name` and
//!   `super::Name` go to the module that defines `Name` (the path is walked down the modules; at a name that
//!   the module reached re-exports, the walk goes on with the re-export's path).
//!
//! The graph builder takes (module name, source text) pairs; the walk of the folders is separate, and the
//! checker is also run on small crates written here, with and without a circle.

use petgraph::algo::tarjan_scc;
use petgraph::graphmap::DiGraphMap;
use regex::Regex;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::fs;
use std::path::Path;

/// Module name -> the modules it uses (the crate root is "").
type Graph = BTreeMap<String, BTreeSet<String>>;

/// Path segments of `a::b::c`.
fn segments(path: &str) -> Vec<String> {
    path.split("::").map(str::to_string).collect()
}

/// The items of a `use ..::{..}` group, each as path segments: `a::{B, C as D}` gives `a::`, `B`, `C`,
/// `as`, `D` (names that lead nowhere stop at the module reached).
fn group_items(group: &str) -> Vec<Vec<String>> {
    group
        .split(|c: char| c == ',' || c == '{' || c == '}' || c.is_whitespace())
        .filter(|item| !item.is_empty())
        .map(segments)
        .collect()
}

/// The module a file under `src/` is, from its path relative to `src/` (`a/b.rs` and `a/b/mod.rs` are
/// `a::b`, `lib.rs` is the root "").
fn module_name(relative_path: &str) -> String {
    let path = relative_path.strip_suffix(".rs").unwrap_or(relative_path);
    let mut parts: Vec<&str> = path.split('/').collect();
    if matches!(parts.last(), Some(&("lib" | "main" | "mod"))) {
        parts.pop();
    }
    parts.join("::")
}

/// The source that is read: up to the first `#[cfg(test)]`, without `//` comments.
fn code(source: &str) -> String {
    let source = source.find("#[cfg(test)]").map_or(source, |i| &source[..i]);
    let comment = Regex::new(r"//[^\n]*").unwrap();
    comment.replace_all(source, "").into_owned()
}

/// A re-export statement: `pub use`, `pub(crate) use`, `pub(super) use`.
const REEXPORT: &str = r"pub(?:\((?:crate|super)\))?\s+use\s+";

/// The names a module re-exports, each with the path of the item it stands for (relative to the module,
/// or from the crate root after `crate::`; `self::` dropped).
fn reexports(s: &str) -> BTreeMap<String, Vec<String>> {
    let group = Regex::new(&format!(
        r"{REEXPORT}(?:self::|crate::)?((?:\w+::)+)\{{([^}}]*)\}}\s*;"
    ))
    .unwrap();
    let single = Regex::new(&format!(
        r"{REEXPORT}(?:self::|crate::)?((?:\w+::)+)(\w+)(?:\s+as\s+(\w+))?\s*;"
    ))
    .unwrap();
    let mut names = BTreeMap::new();
    for c in group.captures_iter(s) {
        let base = segments(c[1].trim_end_matches(':'));
        for item in c[2].split(',') {
            let mut words = item.split_whitespace();
            let (Some(first), last) = (words.next(), words.last()) else {
                continue;
            };
            let mut path = base.clone();
            path.extend(segments(first));
            let name = last.unwrap_or_else(|| path.last().unwrap()).to_string();
            names.insert(name, path);
        }
    }
    for c in single.captures_iter(s) {
        let mut path = segments(c[1].trim_end_matches(':'));
        path.push(c[2].to_string());
        let name = c.get(3).map_or(&c[2], |alias| alias.as_str());
        names.insert(name.to_string(), path);
    }
    names
}

/// The paths, from the crate root, that `module`'s code `s` names: `crate::` paths and groups, `super::`
/// paths and groups, and its children named by `use child::`. Re-export statements are left out.
fn references(module: &str, s: &str, is_module: impl Fn(&str) -> bool) -> Vec<Vec<String>> {
    let s = Regex::new(&format!("{REEXPORT}[^;]*;"))
        .unwrap()
        .replace_all(s, "");
    let own: Vec<String> = segments(module)
        .into_iter()
        .filter(|m| !m.is_empty())
        .collect();
    let parent = &own[..own.len().saturating_sub(1)];
    let mut refs = Vec::new();
    for c in Regex::new(r"crate::((?:\w+::)*\w+)")
        .unwrap()
        .captures_iter(&s)
    {
        refs.push(segments(&c[1]));
    }
    for c in Regex::new(r"use crate::\{([^;]*)\};")
        .unwrap()
        .captures_iter(&s)
    {
        refs.extend(group_items(&c[1]));
    }
    for c in Regex::new(r"\bsuper::((?:\w+::)*\w+)")
        .unwrap()
        .captures_iter(&s)
    {
        refs.push([parent, &segments(&c[1])].concat());
    }
    for c in Regex::new(r"use super::\{([^;]*)\};")
        .unwrap()
        .captures_iter(&s)
    {
        refs.extend(
            group_items(&c[1])
                .iter()
                .map(|item| [parent, item].concat()),
        );
    }
    for c in Regex::new(r"\buse (\w+)::").unwrap().captures_iter(&s) {
        let child = [&own[..], &[c[1].to_string()]].concat();
        if is_module(&child.join("::")) {
            refs.push(child);
        }
    }
    refs
}

/// The module-level import graph of one crate, from its modules' (name, source text); a later source of
/// the same name replaces an earlier one.
fn build_graph(modules: &[(String, String)]) -> Graph {
    let sources: BTreeMap<&str, String> = modules
        .iter()
        .map(|(name, source)| (name.as_str(), code(source)))
        .collect();
    let reexported: BTreeMap<&str, _> = sources.iter().map(|(&m, s)| (m, reexports(s))).collect();
    let is_module = |m: &str| sources.contains_key(m);
    // The module that `parts` (from the crate root) leads to: down the modules, and on through
    // re-exports, as far as it goes.
    let resolve = |mut parts: Vec<String>| {
        let mut at: Vec<String> = Vec::new();
        let mut i = 0;
        for _ in 0..50 {
            let Some(part) = parts.get(i) else { break };
            let next = [&at[..], std::slice::from_ref(part)].concat();
            if is_module(&next.join("::")) {
                at = next;
                i += 1;
                continue;
            }
            let Some(from) = reexported
                .get(at.join("::").as_str())
                .and_then(|r| r.get(part))
            else {
                break;
            };
            // The re-export's path is relative to the module reached, or else from the crate root.
            let relative = from.first().is_some_and(|head| {
                is_module(&[&at[..], std::slice::from_ref(head)].concat().join("::"))
            });
            let head = if relative { at.clone() } else { Vec::new() };
            parts = [head, from.clone(), parts[i + 1..].to_vec()].concat();
            at.clear();
            i = 0;
        }
        at.join("::")
    };
    let mut graph = Graph::new();
    for (&module, s) in &sources {
        let uses = graph.entry(module.to_string()).or_default();
        for parts in references(module, s, is_module) {
            let target = resolve(parts);
            if target != module {
                uses.insert(target);
            }
        }
    }
    graph
}

/// The circles: strongly connected components (Tarjan's, by petgraph) of more than one module, each
/// sorted.
fn circles(graph: &Graph) -> Vec<Vec<String>> {
    let mut g = DiGraphMap::<&str, ()>::new();
    for (module, uses) in graph {
        g.add_node(module);
        for used in uses {
            g.add_edge(module, used, ());
        }
    }
    let mut found: Vec<Vec<String>> = tarjan_scc(&g)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut c: Vec<String> = c.into_iter().map(str::to_string).collect();
            c.sort();
            c
        })
        .collect();
    found.sort();
    found
}

fn shown(module: &str) -> &str {
    if module.is_empty() {
        "<root>"
    } else {
        module
    }
}

/// `['a', 'b']`, sorted as shown.
fn list<'a>(modules: impl IntoIterator<Item = &'a String>) -> String {
    let mut names: Vec<&str> = modules.into_iter().map(|m| shown(m)).collect();
    names.sort();
    let quoted: Vec<String> = names.iter().map(|n| format!("'{n}'")).collect();
    format!("[{}]", quoted.join(", "))
}

/// Each circle, and for each of its modules the modules of the circle that it uses.
fn describe(label: &str, graph: &Graph, circles: &[Vec<String>]) -> String {
    let mut out = String::new();
    for circle in circles {
        writeln!(out, "{label} circle: {}", list(circle)).unwrap();
        for module in circle {
            let inside = graph[module].iter().filter(|m| circle.contains(m));
            writeln!(out, "    {} -> {}", shown(module), list(inside)).unwrap();
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------------
// The workspace's crates on disk.

/// The `members` of the `[workspace]` table.
fn workspace_members(manifest: &str) -> Vec<String> {
    let manifest: toml::Table = manifest.parse().expect("Cargo.toml is TOML");
    let members = manifest["workspace"]["members"]
        .as_array()
        .expect("[workspace] has members");
    let members: Vec<String> = members
        .iter()
        .map(|m| m.as_str().expect("a member is a path").to_string())
        .collect();
    for member in &members {
        assert!(
            !member.contains(['*', '?']),
            "glob member {member:?}: not read here"
        );
    }
    members
}

/// Every `.rs` file under `dir`, as paths relative to `src` with `/`.
fn rust_files(src: &Path, dir: &Path, out: &mut Vec<String>) {
    let entries = fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let entry = entry.unwrap();
        let path = entry.path();
        if entry.file_type().unwrap().is_dir() {
            rust_files(src, &path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(src).unwrap();
            let parts: Vec<_> = relative.iter().map(|p| p.to_string_lossy()).collect();
            out.push(parts.join("/"));
        }
    }
}

/// A crate's modules as (module name, source text). Where two files name one module, `a/mod.rs` is taken
/// over `a.rs` and `lib.rs` over `main.rs` (a binary beside a library uses it by the crate's name).
fn crate_sources(src: &Path) -> Vec<(String, String)> {
    let mut files = Vec::new();
    rust_files(src, src, &mut files);
    let rank = |file: &str| match file.rsplit('/').next() {
        Some("lib.rs") => 3,
        Some("mod.rs") => 2,
        Some("main.rs") => 1,
        _ => 0,
    };
    let mut chosen: BTreeMap<String, String> = BTreeMap::new();
    for file in files {
        let name = module_name(&file);
        if chosen
            .get(&name)
            .is_none_or(|other| rank(&file) > rank(other))
        {
            chosen.insert(name, file);
        }
    }
    chosen
        .into_iter()
        .map(|(name, file)| {
            let path = src.join(&file);
            let source =
                fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            (name, source)
        })
        .collect()
}

#[test]
fn no_import_circles_between_the_modules_of_a_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let manifest = fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let mut report = String::new();
    let mut crates = 0;
    let mut edges = 0;
    for member in workspace_members(&manifest) {
        let src = root.join(&member).join("src");
        if !src.is_dir() {
            continue;
        }
        let modules = crate_sources(&src);
        assert!(!modules.is_empty(), "{member}/src has no modules");
        let graph = build_graph(&modules);
        edges += graph.values().map(BTreeSet::len).sum::<usize>();
        report += &describe(&format!("{member}/src"), &graph, &circles(&graph));
        crates += 1;
    }
    assert!(
        crates > 1 && edges > 0,
        "{crates} crates, {edges} edges read"
    );
    assert!(report.is_empty(), "module graph circles:\n{report}");
}

// ---------------------------------------------------------------------------------------------------
// The checker on crates written here.

/// A crate from (path under `src/`, source) pairs.
fn fake_crate(files: &[(&str, &str)]) -> Vec<(String, String)> {
    let pairs = files
        .iter()
        .map(|(path, source)| (module_name(path), source.to_string()));
    pairs.collect()
}

fn set(modules: &[&str]) -> BTreeSet<String> {
    modules.iter().map(|m| m.to_string()).collect()
}

#[test]
fn checker_finds_the_one_circle_and_none_once_it_is_broken() {
    let a = ("a.rs", "use crate::b::Bee;\npub struct Ay(pub Bee);\n");
    let c = ("c.rs", "use crate::a::Ay;\npub fn see(_: Ay) {}\n");
    let b_uses_a = ("b.rs", "pub struct Bee;\npub fn bee(_: crate::a::Ay) {}\n");
    let graph = build_graph(&fake_crate(&[a, b_uses_a, c]));
    assert_eq!(graph["a"], set(&["b"]));
    assert_eq!(graph["b"], set(&["a"]));
    assert_eq!(graph["c"], set(&["a"]));
    let found = circles(&graph);
    assert_eq!(found, vec![vec!["a".to_string(), "b".to_string()]]);
    assert_eq!(
        describe("src", &graph, &found),
        "src circle: ['a', 'b']\n    a -> ['b']\n    b -> ['a']\n"
    );

    let b_clean = ("b.rs", "pub struct Bee;\n");
    let graph = build_graph(&fake_crate(&[a, b_clean, c]));
    assert_eq!(graph["b"], set(&[]));
    assert!(circles(&graph).is_empty());
}

#[test]
fn reexports_lead_to_the_defining_module_and_are_not_dependencies() {
    let lib = (
        "lib.rs",
        "mod a;\nmod b;\npub mod shapes;\npub use a::Ay;\npub(crate) use b::{Bee, Wasp as Hornet};\n",
    );
    // `crate::Hornet` is `b::Wasp`, through the root's re-export: a circle a <-> b.
    let a = (
        "a.rs",
        "use crate::{shapes::Square, Hornet};\npub struct Ay;\n",
    );
    let b = (
        "b.rs",
        "pub struct Bee;\npub struct Wasp;\npub fn f(_: crate::Ay) {}\n",
    );
    // `super::Circle` is `shapes::round::Circle` through `shapes`' re-export; `use round::..` names a child.
    let shapes = (
        "shapes/mod.rs",
        "mod round;\nmod square;\npub use self::round::Circle;\nuse round::Disc;\npub struct Square;\n",
    );
    let square = ("shapes/square.rs", "pub fn f(_: super::Circle) {}\n");
    let round = (
        "shapes/round.rs",
        "use super::{Square};\npub struct Circle;\npub struct Disc;\n",
    );
    let graph = build_graph(&fake_crate(&[lib, a, b, shapes, round, square]));
    assert_eq!(
        graph[""],
        set(&[]),
        "the root's re-exports are not its dependencies"
    );
    assert_eq!(graph["a"], set(&["b", "shapes"]));
    assert_eq!(graph["b"], set(&["a"]));
    assert_eq!(
        graph["shapes"],
        set(&["shapes::round"]),
        "`mod square;` is no edge"
    );
    assert_eq!(graph["shapes::round"], set(&["shapes"]));
    assert_eq!(graph["shapes::square"], set(&["shapes::round"]));
    let found = circles(&graph);
    assert_eq!(
        describe("src", &graph, &found),
        "src circle: ['a', 'b']\n    a -> ['b']\n    b -> ['a']\n\
         src circle: ['shapes', 'shapes::round']\n    shapes -> ['shapes::round']\n    \
         shapes::round -> ['shapes']\n"
    );
}

#[test]
fn comments_and_test_code_are_not_read() {
    let a = (
        "a.rs",
        "// use crate::b::Bee;\npub struct Ay; // crate::b::Bee\n#[cfg(test)]\nuse crate::b::Bee;\n",
    );
    let b = ("b.rs", "use super::a::Ay;\n");
    let graph = build_graph(&fake_crate(&[a, b]));
    assert_eq!(graph["a"], set(&[]));
    assert_eq!(graph["b"], set(&["a"]));
    assert!(circles(&graph).is_empty());
}

#[test]
fn workspace_members_are_read_from_the_manifest() {
    let manifest = "[package]\nname = \"x\"\n\n\
        [workspace]\nresolver = \"2\"\nmembers = [\n  \"a\", # first\n  \"b/c\",\n]\n\n\
        [workspace.package]\nedition = \"2021\"\n";
    assert_eq!(workspace_members(manifest), ["a", "b/c"]);
    assert_eq!(module_name("lib.rs"), "");
    assert_eq!(module_name("a/b/mod.rs"), "a::b");
    assert_eq!(module_name("a/b.rs"), "a::b");
}
