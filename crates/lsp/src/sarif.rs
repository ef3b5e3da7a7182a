//! `--format sarif`: SARIF 2.1.0, the format code-scanning services read.

use std::{
    collections::{BTreeMap, HashMap},
    io::{self, Write},
    path::Path,
};

use ncc_analysis::{Diagnostic, Rule, Severity, TextRange};
use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, utf8_percent_encode};
use serde_sarif::sarif::{
    self, ArtifactChange, ArtifactContent, ArtifactLocation, Location, Message, MultiformatMessageString,
    PhysicalLocation, Region, Replacement, ReportingConfiguration, ReportingDescriptor, ResultLevel, Run, Sarif, Tool,
    ToolComponent,
};

use crate::report::{Checked, Positions};

/// The base that relative artifact URIs are resolved against.
const SOURCE_ROOT: &str = "SRCROOT";

/// Characters kept as they are in a URI path: RFC 3986 unreserved, and `/`.
const PATH_SEGMENT: &AsciiSet = &NON_ALPHANUMERIC.remove(b'-').remove(b'.').remove(b'_').remove(b'~').remove(b'/');

pub(crate) fn write(out: &mut impl Write, checked: &Checked) -> io::Result<()> {
    let rules: Vec<&Rule> = Rule::all().collect();
    let rule_index: HashMap<&str, usize> = rules.iter().enumerate().map(|(i, rule)| (rule.code, i)).collect();
    let driver = ToolComponent::builder()
        .name("ncc")
        .version(env!("CARGO_PKG_VERSION"))
        .semantic_version(env!("CARGO_PKG_VERSION"))
        .rules(rules.iter().map(|rule| descriptor(rule)).collect::<Vec<_>>())
        .build();

    let mut positions = Artifacts { checked, indexed: HashMap::new() };
    let mut results = Vec::new();
    for file in &checked.files {
        let name = file.path.display().to_string();
        for diagnostic in &file.diagnostics {
            results.push(result(&mut positions, &name, diagnostic, rule_index.get(diagnostic.code).copied()));
        }
    }

    let mut run = Run::builder()
        .tool(Tool::builder().driver(driver).build())
        .results(results)
        .column_kind(serde_json::json!("unicodeCodePoints"))
        .build();
    if let Ok(directory) = std::env::current_dir() {
        let root = ArtifactLocation::builder().uri(format!("{}/", file_uri(&directory))).build();
        run.original_uri_base_ids = Some(BTreeMap::from([(SOURCE_ROOT.to_owned(), root)]));
    }
    let log = Sarif::builder()
        .schema(sarif::SCHEMA_URL)
        .version(serde_json::to_value(sarif::Version::V2_1_0).unwrap_or_default())
        .runs(vec![run])
        .build();
    serde_json::to_writer_pretty(&mut *out, &log)?;
    writeln!(out)
}

fn descriptor(rule: &Rule) -> ReportingDescriptor {
    ReportingDescriptor::builder()
        .id(rule.code)
        .name(rule.name)
        .short_description(MultiformatMessageString::builder().text(rule.summary).build())
        .default_configuration(
            ReportingConfiguration::builder()
                .level(serde_json::to_value(level(rule.severity)).unwrap_or_default())
                .build(),
        )
        .build()
}

fn level(severity: Severity) -> ResultLevel {
    match severity {
        Severity::Error => ResultLevel::Error,
        Severity::Warning => ResultLevel::Warning,
        Severity::Info | Severity::Hint => ResultLevel::Note,
    }
}

/// Line indexes of the files that locations point into, built once each.
struct Artifacts<'a> {
    checked: &'a Checked,
    indexed: HashMap<String, Positions>,
}

impl Artifacts<'_> {
    /// A location in file `name`, with a region when its text is known.
    fn location(&mut self, name: &str, range: TextRange) -> PhysicalLocation {
        let artifact = artifact_location(name);
        let positions = match self.indexed.entry(name.to_owned()) {
            std::collections::hash_map::Entry::Occupied(entry) => Some(entry.into_mut()),
            std::collections::hash_map::Entry::Vacant(entry) => {
                self.checked.source(name).map(|text| entry.insert(Positions::new(text)))
            }
        };
        match positions {
            Some(positions) => {
                PhysicalLocation::builder().artifact_location(artifact).region(region(positions, range)).build()
            }
            None => PhysicalLocation::builder().artifact_location(artifact).build(),
        }
    }
}

fn region(positions: &Positions, range: TextRange) -> Region {
    let (start_line, start_column) = positions.at(range.start());
    let (end_line, end_column) = positions.at(range.end());
    Region::builder()
        .start_line(i64::from(start_line))
        .start_column(i64::from(start_column))
        .end_line(i64::from(end_line))
        .end_column(i64::from(end_column))
        .build()
}

fn result(
    artifacts: &mut Artifacts<'_>,
    file: &str,
    diagnostic: &Diagnostic,
    rule_index: Option<usize>,
) -> sarif::Result {
    let location = artifacts.location(file, diagnostic.range);
    let related: Vec<Location> = diagnostic
        .related
        .iter()
        .enumerate()
        .map(|(id, related)| {
            let other = related.file.as_deref().unwrap_or(file);
            Location::builder()
                .id(id as i64)
                .physical_location(artifacts.location(other, related.range))
                .message(Message::builder().text(&related.message).build())
                .build()
        })
        .collect();
    let fixes: Vec<sarif::Fix> = diagnostic
        .fixes
        .iter()
        .map(|fix| {
            let replacements = fix
                .edits
                .iter()
                .map(|edit| {
                    let deleted = artifacts.location(file, edit.delete).region.unwrap_or_default();
                    Replacement::builder()
                        .deleted_region(deleted)
                        .inserted_content(ArtifactContent::builder().text(&edit.insert).build())
                        .build()
                })
                .collect::<Vec<_>>();
            sarif::Fix::builder()
                .description(Message::builder().text(&fix.title).build())
                .artifact_changes(vec![
                    ArtifactChange::builder()
                        .artifact_location(artifact_location(file))
                        .replacements(replacements)
                        .build(),
                ])
                .build()
        })
        .collect();

    let mut result = sarif::Result::builder()
        .rule_id(diagnostic.code)
        .level(level(diagnostic.severity))
        .message(Message::builder().text(&diagnostic.message).build())
        .locations(vec![Location::builder().physical_location(location).build()])
        .build();
    result.rule_index = rule_index.map(|i| i as i64);
    result.related_locations = (!related.is_empty()).then_some(related);
    result.fixes = (!fixes.is_empty()).then_some(fixes);
    result
}

/// A file as SARIF names it: relative paths against the source root,
/// absolute ones as `file` URIs.
fn artifact_location(name: &str) -> ArtifactLocation {
    let path = Path::new(name);
    if path.is_absolute() {
        ArtifactLocation::builder().uri(file_uri(path)).build()
    } else {
        let relative = name.strip_prefix("./").unwrap_or(name);
        ArtifactLocation::builder()
            .uri(utf8_percent_encode(relative, PATH_SEGMENT).to_string())
            .uri_base_id(SOURCE_ROOT)
            .build()
    }
}

fn file_uri(absolute: &Path) -> String {
    format!("file://{}", utf8_percent_encode(&absolute.to_string_lossy(), PATH_SEGMENT))
}
