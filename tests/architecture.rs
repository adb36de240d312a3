//! The layering of the library, held by a test.
//!
//! `ARCHITECTURE.md` states, between the markers `<!-- allowed-dependencies:begin -->` and
//! `<!-- allowed-dependencies:end -->`, a table of the library's top-level modules and the
//! modules each may use. This test reads every source file under `src/`, finds the paths it
//! names (`crate::a::b`, `super::c`; comments and the `#[cfg(test)]` module at the end of a file
//! left out) and fails
//!
//! * when a module uses a top-level module its row does not allow (an import that breaks the
//!   layers), or a module that the table does not list;
//! * when the table itself has a cycle (layers must be a partial order);
//! * when the modules (one per file, at any depth) have a cycle. A parent module's references to
//!   its own children are left out: a parent declares and re-exports its children, that is
//!   structure and not a dependency; a child's use of its parent (`super::X`) counts.
//!
//! The scan is textual (no compiler): a path is resolved to the deepest module file that
//! exists under `src/`. That is exact for the `use` lines and qualified paths this crate writes.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The module path of a source file: `src/mesh/model.rs` → `["mesh", "model"]`,
/// `src/mesh/mod.rs` → `["mesh"]`, `src/lib.rs` → `[]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> =
        rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether `module` (a path below `src/`) has a file of its own.
fn is_module(src: &Path, module: &[String]) -> bool {
    if module.is_empty() {
        return true;
    }
    let base = module.iter().fold(src.to_path_buf(), |p, m| p.join(m));
    base.with_extension("rs").is_file() || base.join("mod.rs").is_file()
}

/// The source without comments and without a trailing `#[cfg(test)] mod …` block.
fn code_of(text: &str) -> String {
    let mut code = String::new();
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("#[cfg(test)]") {
            // The tests of a module sit at its end; what follows is test code.
            break;
        }
        if trimmed.starts_with("//") {
            continue;
        }
        let line = line.split(" // ").next().unwrap_or(line);
        code.push_str(line);
        code.push('\n');
    }
    code
}

/// The identifiers of a path starting at byte `at` of `code` (`a::b::c` → `[a, b, c]`),
/// including the items of a brace group's first level (`a::{b, c::d}` → `[a]` then the
/// caller resolves `a` only: a group is resolved at its common prefix plus each member).
fn path_at(code: &str, at: usize) -> Vec<Vec<String>> {
    let rest = &code[at..];
    let mut segs = Vec::new();
    let mut i = 0;
    let bytes = rest.as_bytes();
    loop {
        let start = i;
        while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
            i += 1;
        }
        if i == start {
            break;
        }
        segs.push(rest[start..i].to_string());
        if rest[i..].starts_with("::") {
            i += 2;
            if rest[i..].starts_with('{') {
                // A group: each member resolved on its own after the common prefix.
                let end = rest[i..].find('}').map_or(rest.len(), |e| i + e);
                let mut out = Vec::new();
                for member in rest[i + 1..end].split(',') {
                    let m: Vec<String> = member
                        .trim()
                        .split("::")
                        .map(|s| s.trim().to_string())
                        .take_while(|s| {
                            !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || c == '_')
                        })
                        .collect();
                    let mut full = segs.clone();
                    full.extend(m);
                    out.push(full);
                }
                if out.is_empty() {
                    out.push(segs);
                }
                return out;
            }
        } else {
            break;
        }
    }
    vec![segs]
}

/// The modules a file's code refers to (deepest existing module of each path).
fn references(src: &Path, module: &[String], code: &str) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    for (prefix, base) in [("crate::", Vec::new()), ("super::", module.to_vec())] {
        let mut from = 0;
        while let Some(pos) = code[from..].find(prefix) {
            let at = from + pos;
            from = at + prefix.len();
            // `$crate::` (macros) is the crate root as well; skip a `super::` that is part of
            // a longer path (`self::super::`).
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let mut root = base.clone();
            if prefix == "super::" {
                if root.is_empty() {
                    continue;
                }
                // `super::` from a file's module: its parent. Chains `super::super::` follow.
                root.pop();
                let mut k = from;
                while code[k..].starts_with("super::") {
                    root.pop();
                    k += "super::".len();
                }
                from = k;
            }
            for path in path_at(code, from) {
                let mut target = root.clone();
                let mut deepest = root.clone();
                for seg in path {
                    target.push(seg);
                    if is_module(src, &target) {
                        deepest = target.clone();
                    } else {
                        break;
                    }
                }
                out.insert(deepest);
            }
        }
    }
    out
}

/// The allowed table of `ARCHITECTURE.md`: module → modules it may use.
fn allowed_table(doc: &str) -> BTreeMap<String, BTreeSet<String>> {
    let begin = doc
        .find("<!-- allowed-dependencies:begin -->")
        .expect("ARCHITECTURE.md has no `<!-- allowed-dependencies:begin -->` marker");
    let end = doc[begin..]
        .find("<!-- allowed-dependencies:end -->")
        .expect("ARCHITECTURE.md has no `<!-- allowed-dependencies:end -->` marker")
        + begin;
    let mut table = BTreeMap::new();
    for line in doc[begin..end].lines() {
        let cells: Vec<&str> = line.trim().trim_matches('|').split('|').map(str::trim).collect();
        if cells.len() < 2 || !cells[0].starts_with('`') {
            continue;
        }
        let name = cells[0].trim_matches('`').to_string();
        let uses = cells[1]
            .split(',')
            .map(|s| s.trim().trim_matches('`').to_string())
            .filter(|s| !s.is_empty() && s != "—" && s != "-")
            .collect();
        table.insert(name, uses);
    }
    assert!(!table.is_empty(), "the allowed-dependencies table of ARCHITECTURE.md is empty");
    table
}

/// Strongly connected components with more than one node (Tarjan).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        s.index.insert(v, s.next);
        s.low.insert(v, s.next);
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        if let Some(ws) = s.graph.get(v) {
            for w in ws {
                let w = w.as_str();
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
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
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
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The module graph of `src/`: file module → modules it refers to (parent → child left out).
fn module_graph() -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let src = root.join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    // The library's top-level modules are those lib.rs declares (a binary's files beside them,
    // such as main.rs, are not part of the library).
    let lib = code_of(&fs::read_to_string(src.join("lib.rs")).unwrap());
    let tops: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| {
            let l = l.trim().strip_prefix("pub ").unwrap_or(l.trim());
            l.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')).map(|m| m.trim().to_string())
        })
        .collect();
    let mut graph = BTreeMap::new();
    for file in files {
        let module = module_of(&src, &file);
        if module.is_empty() || !tops.contains(&module[0]) {
            continue; // lib.rs declares the modules; other files are not the library's
        }
        let code = code_of(&fs::read_to_string(&file).unwrap());
        let refs = references(&src, &module, &code)
            .into_iter()
            .filter(|r| !r.is_empty() && *r != module && !r.starts_with(&module))
            .collect::<BTreeSet<_>>();
        graph.entry(module).or_insert_with(BTreeSet::new).extend(refs);
    }
    graph
}

fn join(m: &[String]) -> String {
    m.join("::")
}

#[test]
fn imports_respect_the_allowed_dependencies_of_architecture_md() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let table = allowed_table(&doc);
    let graph = module_graph();
    let mut broken = Vec::new();
    for (from, tos) in &graph {
        let top = &from[0];
        let Some(allowed) = table.get(top) else {
            broken.push(format!("module `{top}` is not in the table of ARCHITECTURE.md"));
            continue;
        };
        for to in tos {
            let to_top = &to[0];
            if to_top != top && !allowed.contains(to_top) {
                broken.push(format!(
                    "`{}` uses `{}`: `{top}` may use only {:?} (ARCHITECTURE.md)",
                    join(from),
                    join(to),
                    allowed
                ));
            }
        }
    }
    assert!(broken.is_empty(), "imports that break the layers:\n{}", broken.join("\n"));
}

#[test]
fn the_allowed_table_names_existing_modules_and_is_a_partial_order() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let table = allowed_table(&doc);
    let src = root.join("src");
    for (m, uses) in &table {
        for x in std::iter::once(m).chain(uses) {
            assert!(
                is_module(&src, std::slice::from_ref(x)),
                "ARCHITECTURE.md's table names `{x}`, which is not a module of src/"
            );
        }
    }
    let c = cycles(&table);
    assert!(c.is_empty(), "the allowed table of ARCHITECTURE.md has cycles: {c:?}");
}

#[test]
fn no_module_cycles() {
    let graph: BTreeMap<String, BTreeSet<String>> = module_graph()
        .into_iter()
        .map(|(k, v)| (join(&k), v.iter().map(|m| join(m)).collect()))
        .collect();
    let c = cycles(&graph);
    assert!(c.is_empty(), "module cycles (each list imports itself round the circle): {c:?}");
}
