//! No library crate has an import cycle between its modules: a shared module (say
//! `stencilgen::cone_patch`) must not import the scheme-specific modules built on it
//! (`butterfly_patch`, `sqrt3_patch`), or the layers stop being layers (STYLE.md: "layers with
//! one-way dependencies", OpenSubdiv's Sdc → Vtr → Far). Rust compiles such cycles happily, so
//! nothing but this test keeps them out.
//!
//! The check reads each crate's `src/` tree as text (no parser dependency): comments, string
//! and char literals are blanked, every `#[cfg(test)]` item is dropped (test modules may
//! reach anywhere), and the module paths named in the rest — `crate::a::b`, `super::x`,
//! `self::x`, and `use x::...` of a child module — become edges to the longest existing module
//! prefix. A name re-exported by `pub use` (as `crate::Scalar` for `scalar::Scalar`) resolves to
//! the module it comes from. Edges to the module itself or to its ancestors are ignored (a
//! child reading its parent's items is nesting, not layering). Tarjan's algorithm then finds
//! the strongly connected components; any with two or more modules fails the test, named with
//! one cycle through it and the paths that make each edge.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The crates whose `src/` trees are checked (paths from the workspace root).
const CRATES: [&str; 5] = ["schemes", "stencilgen", "table_format", "tables", "runtime"];

/// One module of a crate: its name (`crate`, `a`, `a::b`) and its non-test code, cleaned.
struct Module {
    name: String,
    code: String,
}

/// A module graph: per module, its edges, each with the first path that made it (evidence for
/// the failure message).
type Graph = BTreeMap<String, BTreeMap<String, String>>;

/// Blank comments (line, nested block, doc), string literals (plain, byte, raw) and char
/// literals, keeping newlines, so that braces and paths inside them are not read as code.
fn clean(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let blank = |out: &mut String, ch: char| out.push(if ch == '\n' { '\n' } else { ' ' });
    let mut i = 0;
    while i < c.len() {
        let at = |k: usize| c.get(i + k).copied().unwrap_or('\0');
        if at(0) == '/' && at(1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if at(0) == '/' && at(1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
        } else if (at(0) == 'r' || (at(0) == 'b' && at(1) == 'r'))
            && !c
                .get(i.wrapping_sub(1))
                .is_some_and(|p| p.is_alphanumeric() || *p == '_')
            && {
                let s = if at(0) == 'b' { 2 } else { 1 };
                let mut k = s;
                while at(k) == '#' {
                    k += 1;
                }
                at(k) == '"'
            }
        {
            // A raw string r#"..."#: it ends at a quote followed by as many hashes.
            i += if at(0) == 'b' { 2 } else { 1 };
            let mut hashes = 0;
            while c[i] == '#' {
                hashes += 1;
                i += 1;
            }
            i += 1;
            while i < c.len() {
                if c[i] == '"' && (1..=hashes).all(|k| c.get(i + k) == Some(&'#')) {
                    i += 1 + hashes;
                    break;
                }
                blank(&mut out, c[i]);
                i += 1;
            }
        } else if at(0) == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    blank(&mut out, c[i]);
                    i += 1;
                }
                if i < c.len() {
                    blank(&mut out, c[i]);
                    i += 1;
                }
            }
            i += 1;
        } else if at(0) == '\'' && (at(1) == '\\' || at(2) == '\'') {
            // A char literal ('x', '\n', '\u{7f}'); a lone quote is a lifetime.
            i += 1;
            while i < c.len() && c[i] != '\'' {
                if c[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
        } else {
            out.push(at(0));
            i += 1;
        }
    }
    out
}

/// A token of cleaned code: an identifier or one punctuation character (`::` is two `:`).
fn tokens(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    for ch in code.chars() {
        if ch.is_alphanumeric() || ch == '_' {
            word.push(ch);
            continue;
        }
        if !word.is_empty() {
            out.push(std::mem::take(&mut word));
        }
        if !ch.is_whitespace() {
            out.push(ch.to_string());
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
}

/// `code` without its `#[cfg(test)]` items (a `mod tests { .. }` block, a `mod tests;`
/// declaration, a test-only function), and the names of the file modules declared test-only.
fn drop_test_items(code: &str) -> (String, Vec<String>) {
    let mut out = String::new();
    let mut test_modules = Vec::new();
    let mut rest = code;
    while let Some(start) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..start]);
        let item = &rest[start + "#[cfg(test)]".len()..];
        // The item ends at its first `;` outside braces or at the brace closing its body.
        let mut depth = 0usize;
        let mut end = item.len();
        for (k, ch) in item.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = k + 1;
                    break;
                }
                _ => {}
            }
        }
        let t = tokens(&item[..end]);
        if t.last().is_some_and(|x| x == ";") {
            if let Some(k) = t.iter().position(|x| x == "mod") {
                test_modules.push(t[k + 1].clone());
            }
        }
        rest = &item[end..];
    }
    out.push_str(rest);
    (out, test_modules)
}

/// Every `.rs` file under `dir`, recursively, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).unwrap_or_else(|e| panic!("reading {}: {e}", d.display())) {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|x| x == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The library modules of the crate whose sources are `files` (`(path under src/, text)`):
/// `lib.rs` is `crate`, `a/b.rs` and `a/b/mod.rs` are `a::b`. `main.rs` and `bin/` are other
/// crates (they reach the library by its name), and test-only file modules are left out.
fn modules(files: &[(String, String)]) -> Vec<Module> {
    let mut out = Vec::new();
    let mut test_only = BTreeSet::new();
    for (path, text) in files {
        if path == "main.rs" || path.starts_with("bin/") {
            continue;
        }
        let mut parts: Vec<&str> = path.trim_end_matches(".rs").split('/').collect();
        if matches!(parts.last(), Some(&"mod") | Some(&"lib")) {
            parts.pop();
        }
        let name = if parts.is_empty() {
            "crate".to_owned()
        } else {
            parts.join("::")
        };
        let (code, tests) = drop_test_items(&clean(text));
        for t in tests {
            test_only.insert(child(&name, &t));
        }
        out.push(Module { name, code });
    }
    out.retain(|m| {
        !test_only
            .iter()
            .any(|t| m.name == *t || m.name.starts_with(&format!("{t}::")))
    });
    out
}

/// The module `name` inside `parent`.
fn child(parent: &str, name: &str) -> String {
    if parent == "crate" {
        name.to_owned()
    } else {
        format!("{parent}::{name}")
    }
}

/// The paths of the use tree or expression path starting at `t[i]`, flattened
/// (`a::{b::C, d}` is `a::b::C` and `a::d`), as segment lists.
fn path_tree(t: &[String], mut i: usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    let mut path = prefix;
    while let Some(seg) = t.get(i) {
        if !seg.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            break;
        }
        path.push(seg.clone());
        let double_colon =
            t.get(i + 1).is_some_and(|x| x == ":") && t.get(i + 2).is_some_and(|x| x == ":");
        if !double_colon {
            break;
        }
        i += 3;
        if t.get(i).is_some_and(|x| x == "{") {
            // A group: each item up to the `,` or `}` at this depth.
            i += 1;
            let mut start = i;
            let mut depth = 0usize;
            while let Some(x) = t.get(i) {
                match x.as_str() {
                    "{" => depth += 1,
                    "}" if depth == 0 => {
                        path_tree(t, start, path.clone(), out);
                        return;
                    }
                    "}" => depth -= 1,
                    "," if depth == 0 => {
                        path_tree(t, start, path.clone(), out);
                        start = i + 1;
                    }
                    _ => {}
                }
                i += 1;
            }
            return;
        }
    }
    out.push(path);
}

/// Whether `t[i]` starts a path into the crate's modules: `crate`, `super` or `self` as a
/// path's first segment anywhere, or a child module of `m` right after `use` (a relative path).
fn starts_path(t: &[String], i: usize, m: &str, names: &BTreeSet<String>) -> bool {
    let prev = i.checked_sub(1).map(|j| t[j].as_str());
    // Not `b` in `a::b`, not `$crate` (a macro's own crate).
    if prev == Some(":") || prev == Some("$") {
        return false;
    }
    match t[i].as_str() {
        // `self` in a group (`use a::{self, b}`) is the group's prefix, read with it.
        "self" => !matches!(prev, Some("{") | Some(",")),
        "crate" | "super" => true,
        name => prev == Some("use") && names.contains(&child(m, name)),
    }
}

/// The path `segs` as read in module `m`, from the crate root (`super` and `self` resolved);
/// `None` for a `super` past the root.
fn anchor(m: &str, segs: &[String]) -> Option<Vec<String>> {
    let mut base: Vec<String> = if m == "crate" {
        Vec::new()
    } else {
        m.split("::").map(str::to_owned).collect()
    };
    let mut rest = segs;
    match rest.first().map(String::as_str) {
        Some("crate") => {
            base.clear();
            rest = &rest[1..];
        }
        Some("self") => rest = &rest[1..],
        _ => {}
    }
    while rest.first().is_some_and(|s| s == "super") {
        base.pop()?;
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// Every module path named in `m`'s code, as `(segments from the crate root, text)`.
fn named_paths(m: &Module, names: &BTreeSet<String>) -> Vec<(Vec<String>, String)> {
    let t = tokens(&m.code);
    let mut raw = Vec::new();
    for i in 0..t.len() {
        if starts_path(&t, i, &m.name, names) {
            path_tree(&t, i, Vec::new(), &mut raw);
        }
    }
    raw.into_iter()
        .filter_map(|segs| Some((anchor(&m.name, &segs)?, segs.join("::"))))
        .collect()
}

/// The module a path (segments from the crate root) refers to: its longest prefix that is a
/// module, followed through that module's `pub use` when the next segment is re-exported.
fn resolve(
    segs: &[String],
    names: &BTreeSet<String>,
    reexports: &BTreeMap<String, BTreeMap<String, String>>,
) -> String {
    let mut k = segs.len();
    let module = loop {
        let candidate = if k == 0 {
            "crate".to_owned()
        } else {
            segs[..k].join("::")
        };
        if k == 0 || names.contains(&candidate) {
            break candidate;
        }
        k -= 1;
    };
    match segs
        .get(k)
        .and_then(|item| reexports.get(&module)?.get(item))
    {
        Some(target) => target.clone(),
        None => module,
    }
}

/// The module graph of one crate's modules.
fn graph(modules: &[Module]) -> Graph {
    let names: BTreeSet<String> = modules.iter().map(|m| m.name.clone()).collect();
    let paths: Vec<Vec<(Vec<String>, String)>> =
        modules.iter().map(|m| named_paths(m, &names)).collect();
    // Re-exports: the last segment of each `pub use` path, mapped to its module.
    let mut reexports: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for m in modules {
        let t = tokens(&m.code);
        for i in 0..t.len() {
            if t[i] != "pub" {
                continue;
            }
            // `pub use` or `pub(crate) use` (any visibility in parentheses).
            let mut j = i + 1;
            if t.get(j).is_some_and(|x| x == "(") {
                while t.get(j).is_some_and(|x| x != ")") {
                    j += 1;
                }
                j += 1;
            }
            if t.get(j).map(String::as_str) != Some("use") {
                continue;
            }
            if !starts_path(&t, j + 1, &m.name, &names) {
                continue; // another crate's item
            }
            let mut tree = Vec::new();
            path_tree(&t, j + 1, Vec::new(), &mut tree);
            for raw in tree {
                let (Some(item), Some(segs)) = (raw.last(), anchor(&m.name, &raw)) else {
                    continue;
                };
                let target = resolve(&segs, &names, &BTreeMap::new());
                if target != m.name {
                    reexports
                        .entry(m.name.clone())
                        .or_default()
                        .insert(item.clone(), target);
                }
            }
        }
    }
    let mut g = Graph::new();
    for (m, paths) in modules.iter().zip(paths) {
        let edges = g.entry(m.name.clone()).or_default();
        for (segs, text) in paths {
            let target = resolve(&segs, &names, &reexports);
            let is_ancestor =
                target == "crate" || target == m.name || m.name.starts_with(&format!("{target}::"));
            if !is_ancestor {
                edges.entry(target).or_insert(text);
            }
        }
    }
    g
}

/// The strongly connected components of `g` with two or more modules (Tarjan).
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.g.get(v).into_iter().flat_map(|e| e.keys()) {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).expect("visited");
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    comp.push(w.to_owned());
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    comp.sort();
                    self.out.push(comp);
                }
            }
        }
    }
    let mut t = Tarjan {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out.sort();
    t.out
}

/// One cycle through the component `comp`, from its first module back to it (breadth-first,
/// so the shortest), with the path that makes each edge.
fn describe(g: &Graph, comp: &[String]) -> String {
    let start = &comp[0];
    let inside: BTreeSet<&String> = comp.iter().collect();
    let mut from: BTreeMap<&String, &String> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    let mut closing = None;
    'search: while let Some(v) = queue.pop_front() {
        for w in g[v].keys().filter(|w| inside.contains(w)) {
            if w == start {
                closing = Some(v);
                break 'search;
            }
            if !from.contains_key(w) {
                from.insert(w, v);
                queue.push_back(w);
            }
        }
    }
    let mut chain = vec![start.clone()];
    let mut v = closing.expect("a component of two or more modules has a cycle");
    while v != start {
        chain.push(v.clone());
        v = from[v];
    }
    chain.push(start.clone());
    chain.reverse();
    let edges: Vec<String> = chain
        .windows(2)
        .map(|w| format!("    {} -> {}  (`{}`)", w[0], w[1], g[&w[0]][&w[1]]))
        .collect();
    format!(
        "cycle {} among {{{}}}:\n{}",
        chain.join(" -> "),
        comp.join(", "),
        edges.join("\n")
    )
}

/// The failure report of one crate, empty when its module graph is acyclic.
fn check(krate: &str, files: &[(String, String)]) -> Vec<String> {
    let g = graph(&modules(files));
    cycles(&g)
        .iter()
        .map(|comp| format!("{krate}: {}", describe(&g, comp)))
        .collect()
}

/// The sources of the workspace crate `krate`: `(path under src/, text)`.
fn sources(krate: &str) -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(krate)
        .join("src");
    rust_files(&src)
        .into_iter()
        .map(|p| {
            let rel = p
                .strip_prefix(&src)
                .expect("under src")
                .to_string_lossy()
                .replace('\\', "/");
            let text = fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (rel, text)
        })
        .collect()
}

#[test]
fn no_crate_has_a_module_import_cycle() {
    let mut failures = Vec::new();
    for krate in CRATES {
        let files = sources(krate);
        assert!(!files.is_empty(), "{krate}: no sources read");
        failures.extend(check(krate, &files));
    }
    assert!(
        failures.is_empty(),
        "module import cycles (a shared module must not import the modules built on it):\n{}",
        failures.join("\n")
    );
}

/// A synthetic crate's files.
fn fake(files: &[(&str, &str)]) -> Vec<(String, String)> {
    files
        .iter()
        .map(|(p, t)| (p.to_string(), t.to_string()))
        .collect()
}

#[test]
fn the_check_finds_a_cycle_and_names_it() {
    // The shape this test was written against: the shared module reading a specific one.
    let files = fake(&[
        (
            "lib.rs",
            "pub mod cone;\npub mod butterfly;\npub mod sqrt3;\n",
        ),
        (
            "cone.rs",
            "use crate::butterfly::policy;\npub fn shared() {}\n",
        ),
        (
            "butterfly.rs",
            "pub use crate::cone::shared;\npub fn policy() {}\n",
        ),
        ("sqrt3.rs", "use super::cone::{self, shared};\n"),
    ]);
    let failures = check("fake", &files);
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(
        failures[0].contains("butterfly -> cone -> butterfly"),
        "{}",
        failures[0]
    );
    assert!(
        failures[0].contains("crate::butterfly::policy"),
        "{}",
        failures[0]
    );
}

#[test]
fn the_check_reads_groups_reexports_and_nested_super() {
    // `crate::Item` through the root's re-export, a grouped `use`, `super::super` from a
    // folder module: each closes a cycle on its own.
    let via_reexport = fake(&[
        ("lib.rs", "pub mod a;\npub mod b;\npub use b::Item;\n"),
        ("a.rs", "use crate::Item;\n"),
        ("b.rs", "fn f() { crate::a::g(); }\n"),
    ]);
    assert_eq!(check("fake", &via_reexport).len(), 1);
    let via_group = fake(&[
        ("lib.rs", "pub mod a;\npub mod b;\n"),
        ("a.rs", "use crate::{b::{X, Y}, c};\n"),
        ("b.rs", "use crate::a::Z;\n"),
    ]);
    assert_eq!(check("fake", &via_group).len(), 1);
    let via_super = fake(&[
        ("lib.rs", "pub mod x;\npub mod y;\n"),
        ("x/mod.rs", "pub mod inner;\n"),
        ("x/inner.rs", "use super::super::y::Thing;\n"),
        ("y.rs", "use crate::x::inner::Other;\n"),
    ]);
    assert_eq!(check("fake", &via_super).len(), 1);
}

#[test]
fn the_check_ignores_tests_comments_strings_and_ancestors() {
    let files = fake(&[
        (
            "lib.rs",
            "pub mod a;\npub mod b;\n#[cfg(test)]\nmod tests;\n",
        ),
        (
            "a.rs",
            "//! See [`crate::b`].\n/* crate::b::x */\nuse crate::b::Thing;\n\
             const S: &str = \"crate::b\"; const R: &str = r#\"{\"#; const C: char = '{';\n\
             #[cfg(test)]\nmod tests {\n    use crate::b;\n    fn f() { let _ = \"}\"; }\n}\n",
        ),
        (
            "b.rs",
            "/// Uses [`crate::a`].\nfn f() {}\n#[cfg(test)]\nmod tests { use crate::a::X; }\n",
        ),
        ("tests.rs", "use crate::a; use crate::b;\n"),
    ]);
    assert!(check("fake", &files).is_empty());
    // A child reading its parent (or the root) is nesting, not a cycle.
    let nested = fake(&[
        ("lib.rs", "pub mod p;\nuse p::q::Item;\n"),
        ("p/mod.rs", "pub mod q;\nuse self::q::Item;\n"),
        ("p/q.rs", "use super::Shared; use crate::Root;\n"),
    ]);
    assert!(check("fake", &nested).is_empty());
}
