//! Rules of the code base that no compiler checks, after rust-analyzer's
//! "tidy" tests: where a dialect's knowledge may be, how long a file may
//! grow, and that the modules of a crate do not depend on each other in a
//! circle.
//!
//! Dialect knowledge (a G or M code, a group index, a dialect's catalogue
//! named outright) belongs in the dialect's own modules, directories named
//! after it (`cnc8x6/`, `haas_lathe/`); everything else is neutral and serves every
//! dialect. The code base is moving there: `DIALECT_DEBT` lists the neutral
//! files that still hold such knowledge and how much. The test fails when a
//! file gets more, or less without the list following, so the list only
//! shrinks.

use std::{
    collections::{BTreeMap, BTreeSet},
    path::{Path, PathBuf},
};

/// Directories and files that belong to one dialect, by the dialect's name
/// as a module (`haas_lathe`) or as a data set (`haas-lathe`).
const DIALECT_MODULES: &[&str] = &["cnc8x6", "haas_lathe", "haas_lathe.rs", "haas-lathe", "sinumerik"];

/// The registry: the one file that names every dialect and the files each
/// is the default for.
const REGISTRY: &[&str] = &["crates/catalog/src/dialect_id.rs"];

/// Neutral files that still test code numbers or group indexes, or name a
/// dialect's catalogue, with how many places: moving them into a dialect
/// module takes them off.
const DIALECT_DEBT: &[(&str, usize)] = &[("crates/lsp/src/run.rs", 2)];

/// Cycles between a crate's modules still to be broken, each as its
/// modules in order.
const CYCLE_DEBT: &[&str] = &[];

/// Lines a file may have without saying why in its header.
const LONG_FILE: usize = 1500;

/// The phrase that gives a long file's reason in its header.
const LONG_FILE_REASON: &str = "This file is long because";

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// Every Rust source file of the crates, relative to the workspace.
fn sources() -> Vec<(String, String)> {
    let root = workspace();
    let mut files = Vec::new();
    let mut stack = vec![root.join("crates")];
    while let Some(directory) = stack.pop() {
        for entry in std::fs::read_dir(&directory).unwrap() {
            let path = entry.unwrap().path();
            let name = path.strip_prefix(&root).unwrap().display().to_string();
            if path.is_dir() {
                if !name.ends_with("/target") && !name.ends_with("/test_data") {
                    stack.push(path);
                }
            } else if name.ends_with(".rs") && name.contains("/src/") {
                files.push((name, std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

fn is_dialect_module(path: &str) -> bool {
    path.split('/').any(|component| DIALECT_MODULES.contains(&component))
}

/// The code of a file without its unit tests: tests may name any code.
fn code_of<'t>(path: &str, text: &'t str) -> &'t str {
    if path.ends_with("/tests.rs") || path.contains("/src/tests/") {
        return "";
    }
    let end = text.find("#[cfg(test)]\nmod tests {").unwrap_or(text.len());
    &text[..end]
}

/// Places in `code` that hold a dialect's knowledge: a G or M letter as a
/// byte or char (`b'G'`, `'M'`), a code written out (`"G79"`), a group read
/// by index (`.g(6)`, `m[4]`), or a dialect named outright other than in
/// a match arm that dispatches on it.
fn dialect_knowledge(code: &str) -> usize {
    let lines = code.lines().map(str::trim_start).filter(|line| !line.starts_with("//"));
    lines.map(knowledge_in_line).sum()
}

fn knowledge_in_line(line: &str) -> usize {
    let bytes = line.as_bytes();
    // A match arm `Dialect::Cnc8x6 =>` dispatches to the dialect's module:
    // that is where a new dialect joins, not knowledge of one.
    let mut found = line.matches("Dialect::Cnc8x6").count() - line.matches("Dialect::Cnc8x6 =>").count();
    for (i, &byte) in bytes.iter().enumerate() {
        let before = |n: usize| i.checked_sub(n).map(|at| bytes[at]);
        let after = |n: usize| bytes.get(i + n).copied();
        let letter = matches!(byte, b'G' | b'M' | b'g' | b'm');
        // `'G'` and `b'G'`, not a lifetime or a word ending in G.
        if letter
            && before(1) == Some(b'\'')
            && after(1) == Some(b'\'')
            && !before(2).is_some_and(|b| b.is_ascii_alphanumeric() && b != b'b')
        {
            found += 1;
        }
        // `"G79"`: a quote, the letter, digits, a quote.
        if matches!(byte, b'G' | b'M') && before(1) == Some(b'"') {
            let digits = bytes[i + 1..].iter().take_while(|b| b.is_ascii_digit()).count();
            if digits > 0 && after(1 + digits) == Some(b'"') {
                found += 1;
            }
        }
        // `.g(6)`, `m[4]`, `g[6]`: a group by its index.
        if matches!(byte, b'g' | b'm')
            && !before(1).is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_')
            && matches!(after(1), Some(b'(' | b'['))
            && after(2).is_some_and(|b| b.is_ascii_digit())
        {
            found += 1;
        }
    }
    found
}

#[test]
fn dialect_knowledge_stays_in_dialect_modules() {
    let debt: BTreeMap<&str, usize> = DIALECT_DEBT.iter().copied().collect();
    let mut found = BTreeMap::new();
    for (path, text) in sources() {
        if is_dialect_module(&path) || REGISTRY.contains(&path.as_str()) {
            continue;
        }
        let places = dialect_knowledge(code_of(&path, &text));
        if places > 0 {
            found.insert(path, places);
        }
    }
    let mut problems = Vec::new();
    for (path, &places) in &found {
        match debt.get(path.as_str()) {
            None => problems.push(format!("{path}: {places} places of dialect knowledge in a neutral file")),
            Some(&listed) if places > listed => {
                problems.push(format!("{path}: {places} places of dialect knowledge, {listed} before"))
            }
            Some(&listed) if places < listed => {
                problems.push(format!("{path}: {places} places now, {listed} listed: lower DIALECT_DEBT"))
            }
            Some(_) => {}
        }
    }
    for path in debt.keys().filter(|path| !found.contains_key(**path)) {
        problems.push(format!("{path}: neutral now (or gone): take it off DIALECT_DEBT"));
    }
    assert!(problems.is_empty(), "{}\n(move dialect knowledge into a `cnc8x6` module)", problems.join("\n"));
}

#[test]
fn long_files_say_why() {
    let long: Vec<String> = sources()
        .into_iter()
        .filter(|(_, text)| text.lines().count() > LONG_FILE)
        .filter(|(_, text)| !text.lines().take(30).any(|line| line.contains(LONG_FILE_REASON)))
        .map(|(path, text)| format!("{path}: {} lines", text.lines().count()))
        .collect();
    assert!(
        long.is_empty(),
        "files over {LONG_FILE} lines without \"{LONG_FILE_REASON} …\" in their header:\n{}",
        long.join("\n")
    );
}

/// The top-level modules of a crate each of its top-level modules uses.
fn module_graph(files: &[(String, String)], krate: &str) -> BTreeMap<String, BTreeSet<String>> {
    let prefix = format!("crates/{krate}/src/");
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (path, text) in files {
        let Some(inside) = path.strip_prefix(&prefix) else { continue };
        let module = inside.split(['/', '.']).next().unwrap().to_owned();
        if matches!(module.as_str(), "lib" | "main") {
            continue;
        }
        let uses = graph.entry(module.clone()).or_default();
        let mut code = code_of(path, text).to_owned();
        // In a top-level module, `super` is the crate.
        if !inside.contains('/') {
            code = code.replace("super::", "crate::");
        }
        for used in used_modules(&code) {
            if used != module {
                uses.insert(used);
            }
        }
    }
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    for uses in graph.values_mut() {
        uses.retain(|used| modules.contains(used));
    }
    graph
}

/// The modules `code` names after `crate::`, in paths and in `use crate::{a, b::c}` lists.
fn used_modules(code: &str) -> BTreeSet<String> {
    let mut used = BTreeSet::new();
    let ident = |text: &str| -> String { text.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect() };
    for (at, _) in code.match_indices("crate::") {
        let rest = &code[at + "crate::".len()..];
        if let Some(list) = rest.strip_prefix('{') {
            // A `use crate::{…}` list: each top-level name in it.
            let mut depth = 0;
            let mut start = true;
            for (i, c) in list.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && (c.is_alphanumeric() || c == '_') => {
                        used.insert(ident(&list[i..]));
                        start = false;
                    }
                    _ => {}
                }
            }
        } else {
            used.insert(ident(rest));
        }
    }
    used
}

/// Cycles of `graph`: each strongly connected set of two or more modules,
/// in order, joined by ` → `.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let reaches = |from: &str, to: &str| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_owned()];
        while let Some(module) = stack.pop() {
            for next in graph.get(&module).into_iter().flatten() {
                if next == to {
                    return true;
                }
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        false
    };
    let mut done = BTreeSet::new();
    let mut found = Vec::new();
    for module in graph.keys() {
        if done.contains(module) || !reaches(module, module) {
            continue;
        }
        let members: Vec<&String> = graph
            .keys()
            .filter(|other| *other == module || (reaches(module, other) && reaches(other, module)))
            .collect();
        done.extend(members.iter().map(|m| (*m).clone()));
        found.push(members.iter().map(|m| m.as_str()).collect::<Vec<_>>().join(" → "));
    }
    found
}

#[test]
fn modules_of_a_crate_depend_on_each_other_without_cycles() {
    let files = sources();
    let crates: BTreeSet<String> =
        files.iter().filter_map(|(path, _)| Some(path.split('/').nth(1)?.to_owned())).collect();
    let mut found = Vec::new();
    for krate in &crates {
        for cycle in cycles(&module_graph(&files, krate)) {
            found.push(format!("{krate}: {cycle}"));
        }
    }
    let debt: Vec<String> = CYCLE_DEBT.iter().map(|cycle| cycle.to_string()).collect();
    let new: Vec<&String> = found.iter().filter(|cycle| !debt.contains(cycle)).collect();
    let gone: Vec<&String> = debt.iter().filter(|cycle| !found.contains(cycle)).collect();
    assert!(new.is_empty() && gone.is_empty(), "module cycles: {new:#?}\nbroken, take off CYCLE_DEBT: {gone:#?}");
}

#[test]
fn the_checks_see_what_they_look_for() {
    assert_eq!(knowledge_in_line("if (letter, number) == (b'G', 71) {"), 1);
    assert_eq!(knowledge_in_line("state.g(6) == Some(0) && m[4]"), 2);
    assert_eq!(knowledge_in_line(r#"code == "G79" || Dialect::Cnc8x6.catalogue()"#), 2);
    assert_eq!(knowledge_in_line("fn f<'g>(x: &'g str, tag: u8) -> Big { bg(1) }"), 0);
    assert_eq!(used_modules("use crate::{run::{Step, Trace}, velocity};\nlet x = crate::machine::X;"), {
        ["machine", "run", "velocity"].into_iter().map(str::to_owned).collect()
    });
    let graph: BTreeMap<String, BTreeSet<String>> = [("a", &["b"][..]), ("b", &["c"]), ("c", &["a"]), ("d", &["a"])]
        .into_iter()
        .map(|(m, uses)| (m.to_owned(), uses.iter().map(|u| u.to_string()).collect()))
        .collect();
    assert_eq!(cycles(&graph), ["a → b → c"]);
}
