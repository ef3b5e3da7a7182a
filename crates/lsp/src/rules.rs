//! `ncc rules`: the diagnostics `ncc check` can report.

use std::process::ExitCode;

use ncc_analysis::Rule;

pub(crate) fn run(query: Option<&str>) -> ExitCode {
    let Some(query) = query else {
        print!("{}", table(Rule::all()));
        return ExitCode::SUCCESS;
    };
    let found: Vec<&Rule> = Rule::all()
        .filter(|rule| rule.code.eq_ignore_ascii_case(query) || rule.name.contains(&query.to_ascii_lowercase()))
        .collect();
    if found.is_empty() {
        eprintln!("error: no rule has the code or a name containing `{query}`");
        eprintln!("help: `ncc rules` lists them all");
        return ExitCode::from(1);
    }
    print!("{}", table(found.into_iter()));
    ExitCode::SUCCESS
}

/// One rule per line: code, severity, name, summary.
fn table<'a>(rules: impl Iterator<Item = &'a Rule>) -> String {
    let rules: Vec<&Rule> = rules.collect();
    let width = rules.iter().map(|rule| rule.name.len()).max().unwrap_or(0);
    let mut out = String::new();
    for rule in &rules {
        out.push_str(&format!(
            "{}  {:<7}  {:<width$}  {}\n",
            rule.code,
            rule.severity.as_str(),
            rule.name,
            rule.summary
        ));
    }
    out.push_str(&format!("{} rules\n", rules.len()));
    out
}
