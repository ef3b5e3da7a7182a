//! `ncc explain`: the catalogue's text for a code, like `rustc --explain`,
//! and the rule a diagnostic's code names (`K105`).

use std::process::ExitCode;

use ncc_analysis::Rule;
use ncc_catalog::{Catalogue, Dialect};

/// Explains `query` in `dialect`'s catalogue (the default dialect's when
/// none is named: a query names no program to take one from).
pub(crate) fn run(query: Option<&str>, list: bool, dialect: Option<Dialect>) -> ExitCode {
    let dialect = dialect.unwrap_or_default();
    let catalogue = dialect.catalogue();
    if list {
        print!("{}", listing(catalogue));
        return ExitCode::SUCCESS;
    }
    let query = query.unwrap_or_default();
    // A diagnostic's code first; the catalogue may read the same letters
    // as an address with a value.
    let rule = Rule::all().find(|rule| rule.code.eq_ignore_ascii_case(query));
    if let Some(rule) = rule {
        print!("{}", crate::rules::markdown(rule));
    }
    match catalogue.explain(query) {
        Ok(items) => {
            let texts: Vec<String> = items.iter().map(|item| item.markdown(catalogue)).collect();
            if rule.is_some() {
                println!();
            }
            print!("{}", texts.join("\n"));
            ExitCode::SUCCESS
        }
        Err(_) if rule.is_some() => ExitCode::SUCCESS,
        Err(not_found) => {
            eprintln!(
                "error: `{}` is not a code, address, parameter, machine constant or operation of {}",
                not_found.query,
                dialect.title()
            );
            if !not_found.suggestions.is_empty() {
                eprintln!("help: did you mean {}?", not_found.suggestions.join(", "));
            }
            eprintln!("help: `ncc explain --list` shows everything that can be explained");
            ExitCode::from(1)
        }
    }
}

/// Every entry by kind, with counts.
fn listing(catalogue: &Catalogue) -> String {
    let mut out = String::new();
    let mut section = |title: &str, names: Vec<String>| {
        out.push_str(&format!("{title} ({}):\n", names.len()));
        for line in names.chunks(12) {
            out.push_str(&format!("  {}\n", line.join(" ")));
        }
    };
    section("groups", catalogue.groups.iter().map(|g| format!("group:{}", g.id)).collect());
    for letter in catalogue.function_letters().map(char::from) {
        let codes = catalogue.codes.iter().filter(|c| !c.is_word() && c.code.starts_with(letter));
        section(&format!("{letter} codes"), codes.map(|c| c.code.clone()).collect());
    }
    let words: Vec<String> = catalogue.codes.iter().filter(|c| c.is_word()).map(|c| c.code.clone()).collect();
    if !words.is_empty() {
        section("G group words", words);
    }
    section("addresses", catalogue.addresses.iter().map(|a| a.letter.clone()).collect());
    section("program parameters", (0..catalogue.parameters.count).map(|n| format!("R{n}")).collect());
    section(
        "machine constants",
        catalogue
            .machine_constants
            .iter()
            .map(|c| match c.last.filter(|&l| l != c.number) {
                Some(last) => format!("mc:{}-{last}", c.number),
                None => format!("mc:{}", c.number),
            })
            .collect(),
    );
    section("operations", catalogue.operations.iter().map(|op| format!("op:{}", op.code)).collect());
    section(
        "fixed cycles",
        catalogue.cycles.iter().map(|c| format!("{}({})", c.code, format!("{:?}", c.flavour).to_lowercase())).collect(),
    );
    let mut language = |title: &str, names: Vec<String>| {
        if !names.is_empty() {
            section(title, names);
        }
    };
    language("keywords", catalogue.keywords.iter().map(|k| k.word.clone()).collect());
    language("functions", catalogue.functions.iter().map(|f| f.name.clone()).collect());
    language("system variables", catalogue.system_variables.iter().map(|v| v.name.clone()).collect());
    language(
        "system variable prefixes",
        catalogue.variable_prefixes.iter().map(|p| format!("{}…", p.prefix)).collect(),
    );
    out
}
