//! Hover and `ncc explain` text: Markdown rendered from the entries.
//!
//! The same text serves the terminal and the editor, so it is plain
//! Markdown that reads well unrendered.

use std::fmt::Write;

use crate::{
    Access, AddressRole, Catalogue, Dimensional, Documented, Flavour, Item, KeywordKind, Modality, ParameterOverview,
    ParameterStatus, schema::Doc,
};

impl Item<'_> {
    /// A one-line heading: `G41 — Radius compensation left`.
    pub fn heading(&self, catalogue: &Catalogue) -> String {
        match *self {
            Item::Group(group) => format!("Group {} — {}", group.id, group.title),
            Item::Code(code) => format!("{} — {}", code.code, code.title),
            Item::UnlistedCode { letter, number, group } if group.open => {
                format!("{letter}{number:02} — machine-defined function (group {})", group.id)
            }
            Item::UnlistedCode { letter, number, group } => {
                format!("{letter}{number:02} — {} (group {})", group.title, group.id)
            }
            Item::Address(address) => format!("{} — {}", address.letter, address.title),
            Item::Parameter(number) => {
                let role = catalogue.parameter_ranges_of(number).next().map(|r| r.title.as_str());
                let ParameterOverview { written, noun, .. } = &catalogue.parameters;
                match role {
                    Some(role) => format!("{written}{number} — {noun} ({role})"),
                    None => format!("{written}{number} — {noun}"),
                }
            }
            Item::MachineConstant { number, constant } => {
                let terms = &catalogue.constant_terms;
                format!("{}{number} — {}: {}", terms.written, terms.noun, constant.title)
            }
            Item::Operation(op) => format!("Operation {} — {}", op.code, op.title),
            Item::Cycle(cycle) => {
                let flavour = match cycle.flavour {
                    Flavour::Milling => "milling",
                    Flavour::Lathe => "lathe",
                };
                format!("{} ({flavour} cycle) — {}", cycle.code, cycle.title)
            }
            Item::Keyword(keyword) => format!("{} — {}", keyword.word, keyword.title),
            Item::Function(function) => format!("{} — {}", function.name, function.title),
            Item::SystemVariable(variable) => format!("{} — {}", variable.name, variable.title),
            Item::UndocumentedVariable(prefix) => {
                format!("{}… — a system variable ncc does not document ({})", prefix.prefix, prefix.title)
            }
        }
    }

    /// The full text.
    pub fn markdown(&self, catalogue: &Catalogue) -> String {
        let mut out = format!("### {}\n\n", self.heading(catalogue));
        match *self {
            Item::Group(group) => {
                facts(
                    &mut out,
                    &[
                        ("Default", group.default.clone()),
                        ("Default note", group.default_note.clone()),
                        (
                            "Defined by",
                            group.configured_by.as_ref().map(|c| format!("{} {c}", catalogue.constant_terms.noun)),
                        ),
                        ("Codes", Some(codes_of(catalogue, &group.id)).filter(|c| !c.is_empty())),
                    ],
                );
                doc(&mut out, group.doc());
            }
            Item::Code(code) => {
                let group = code.group.as_deref().and_then(|id| catalogue.group(id));
                let group_text = match group {
                    Some(g) => Some(format!("{} ({})", g.id, g.title)),
                    None => Some("none (not in the address dictionary's groups)".to_owned()),
                };
                let listed = (!code.in_dictionary)
                    .then(|| "used in the manual's text, absent from the address dictionary".to_owned());
                facts(
                    &mut out,
                    &[
                        ("Group", group_text),
                        ("Modality", Some(modality(code.modality).to_owned())),
                        ("Reset default", code.reset_default.then(|| "yes".to_owned())),
                        ("Listed", listed),
                        ("Requires", list(&code.requires)),
                        ("Reads", list(&code.allows)),
                        ("Cancels", list(&code.cancels)),
                        ("Units", code.units.clone()),
                        (
                            "Number in its group",
                            code.index.zip(group).map(|(index, group)| {
                                let number = group.id.trim_start_matches(|c: char| c.is_ascii_alphabetic());
                                format!("{index} (`$P_GG[{number}]` reads it, `G[{number}]={index}` selects it)")
                            }),
                        ),
                    ],
                );
                syntax(&mut out, &code.syntax);
                doc(&mut out, code.doc());
            }
            Item::UnlistedCode { group, .. } => {
                if group.open {
                    let _ = writeln!(
                        out,
                        "The manual does not define this code; it belongs to group {} ({}), whose functions the machine builder defines in the PLC program.\n",
                        group.id, group.title
                    );
                } else if let Some([first, last]) = &group.takes_unlisted {
                    let _ = writeln!(
                        out,
                        "One of the codes {first}–{last} of group {} ({}), which the catalogue describes together.\n",
                        group.id, group.title
                    );
                }
                doc(&mut out, group.doc());
            }
            Item::Address(address) => {
                let range = match (&address.min, &address.max) {
                    (Some(min), Some(max)) => Some(format!("{min} … {max}")),
                    _ => None,
                };
                facts(
                    &mut out,
                    &[
                        ("Role", Some(role(address.role).to_owned())),
                        ("Dimensional", Some(dimensional(address.dimensional).to_owned())),
                        ("Format", address.format.clone()),
                        ("Range", range),
                        ("Signed", Some(if address.signed { "yes" } else { "no" }.to_owned())),
                        ("Units", address.units.clone()),
                        (
                            "Parameter substitution",
                            Some(if address.substitutable {
                                let ParameterOverview { written, value_separator, .. } = &catalogue.parameters;
                                format!("allowed (e.g. `{}{value_separator}{written}1`)", address.letter)
                            } else {
                                "not allowed".to_owned()
                            }),
                        ),
                        ("Modality", address.modality.map(|m| modality(m).to_owned())),
                        (
                            "Axis letter",
                            address
                                .configurable_axis
                                .then(|| "assignable to axis 4, 5 or 6 by the machine configuration".to_owned()),
                        ),
                        (
                            "Listed",
                            (!address.in_dictionary)
                                .then(|| "used in the manual's text, absent from the address dictionary".to_owned()),
                        ),
                    ],
                );
                doc(&mut out, address.doc());
            }
            Item::Parameter(number) => {
                let ParameterOverview { written, noun, count, .. } = &catalogue.parameters;
                let _ = writeln!(out, "{} {number} of {written}0–{written}{}.\n", capitalised(noun), count - 1);
                for range in catalogue.parameter_ranges_of(number) {
                    let _ = writeln!(out, "**{}** ({}): {}\n", range.title, status(range.status), range.summary);
                    if !range.details.is_empty() {
                        let _ = writeln!(out, "{}\n", range.details.trim());
                    }
                }
                doc(&mut out, catalogue.parameters.doc());
            }
            Item::MachineConstant { constant, .. } => {
                let terms = &catalogue.constant_terms;
                let run = constant
                    .last
                    .filter(|&last| last != constant.number)
                    .map(|last| format!("{0}{1}–{0}{last}", terms.written, constant.number));
                let _ = writeln!(out, "{}\n", terms.kept);
                facts(
                    &mut out,
                    &[
                        ("Described together", run),
                        ("Unit", constant.unit.clone()),
                        ("Default", constant.default.clone()),
                    ],
                );
                if !constant.decades.is_empty() {
                    out.push_str("| Decades | Meaning |\n|---|---|\n");
                    for field in &constant.decades {
                        let _ = writeln!(out, "| {} | {} |", field.decades, field.meaning.replace('\n', " "));
                    }
                    out.push('\n');
                }
                doc(&mut out, constant.doc());
            }
            Item::Operation(op) => {
                facts(
                    &mut out,
                    &[
                        ("Defined", (!op.defined).then(|| "no: the manual leaves this code undefined".to_owned())),
                        ("Written", op.symbol.as_ref().map(|symbol| format!("`{symbol}`"))),
                        ("Precedence", op.precedence.map(|level| format!("{level} (1 binds tightest)"))),
                        ("Operands", Some(op.operands.clone())),
                        ("Result", Some(op.result.clone())),
                        ("Conditional", op.conditional.then(|| "yes".to_owned())),
                        ("Real and integer", op.modes.clone()),
                        ("Errors", op.errors.clone()),
                    ],
                );
                doc(&mut out, op.doc());
            }
            Item::Cycle(cycle) => {
                let constants = cycle.machine_constants.iter().map(u32::to_string).collect::<Vec<_>>();
                facts(&mut out, &[("Cycle file", cycle.file.clone()), ("Machine constants read", list(&constants))]);
                if !cycle.addresses.is_empty() {
                    out.push_str("| Address | Meaning | Unit |\n|---|---|---|\n");
                    for a in &cycle.addresses {
                        let _ = writeln!(
                            out,
                            "| {} | {} | {} |",
                            a.letter,
                            a.meaning.replace('\n', " "),
                            a.unit.as_deref().unwrap_or("")
                        );
                    }
                    out.push('\n');
                }
                if !cycle.arguments.is_empty() {
                    let names: Vec<&str> = cycle.arguments.iter().map(|a| a.name.as_str()).collect();
                    let _ = writeln!(out, "`{}({})`\n", cycle.code, names.join(", "));
                    out.push_str("| # | Argument | Type | Meaning | Unit |\n|---|---|---|---|---|\n");
                    for (number, a) in cycle.arguments.iter().enumerate() {
                        let _ = writeln!(
                            out,
                            "| {} | {} | {} | {} | {} |",
                            number + 1,
                            a.name,
                            a.ty,
                            a.meaning.replace('\n', " "),
                            a.unit.as_deref().unwrap_or("")
                        );
                    }
                    out.push('\n');
                }
                if !cycle.parameters.is_empty() {
                    out.push_str("| Parameter | Meaning | Unit |\n|---|---|---|\n");
                    for p in &cycle.parameters {
                        let _ = writeln!(
                            out,
                            "| {}{} | {} | {} |",
                            catalogue.parameters.written,
                            p.r,
                            p.meaning.replace('\n', " "),
                            p.unit.as_deref().unwrap_or("")
                        );
                    }
                    out.push('\n');
                }
                doc(&mut out, cycle.doc());
            }
            Item::Keyword(keyword) => {
                facts(
                    &mut out,
                    &[("Kind", Some(keyword_kind(keyword.kind).to_owned())), ("Goes with", list(&keyword.related))],
                );
                syntax(&mut out, &keyword.syntax);
                doc(&mut out, keyword.doc());
            }
            Item::Function(function) => {
                let kind = if function.returns.is_some() { "function" } else { "procedure (a statement of its own)" };
                facts(&mut out, &[("Kind", Some(kind.to_owned()))]);
                let _ = writeln!(out, "```\n{}\n```\n", function.signature());
                if !function.parameters.is_empty() {
                    out.push_str("| Parameter | Type | Meaning |\n|---|---|---|\n");
                    for p in &function.parameters {
                        let optional = if p.optional { " (may be left out)" } else { "" };
                        let _ = writeln!(out, "| {} | {} | {}{optional} |", p.name, p.ty, p.meaning.replace('\n', " "));
                    }
                    out.push('\n');
                }
                doc(&mut out, function.doc());
            }
            Item::SystemVariable(variable) => {
                let access = match variable.access {
                    Access::Read => "read only",
                    Access::ReadWrite => "read and write",
                };
                facts(
                    &mut out,
                    &[
                        ("Type", Some(variable.ty.clone())),
                        ("Access", Some(access.to_owned())),
                        ("Index", variable.index.as_ref().map(|index| format!("`{}[…]`: {index}", variable.name))),
                        (
                            "Value",
                            Some(
                                if variable.main_run {
                                    "current (main run); reading it outside a synchronous action stops preprocessing"
                                } else {
                                    "programmed (preprocessing)"
                                }
                                .to_owned(),
                            ),
                        ),
                    ],
                );
                doc(&mut out, variable.doc());
            }
            Item::UndocumentedVariable(prefix) => {
                let _ = writeln!(
                    out,
                    "The catalogue does not list this variable; its prefix `{}` says what kind it is. A program may use it: the control decides whether it exists.\n",
                    prefix.prefix
                );
                doc(&mut out, prefix.doc());
            }
        }
        out.truncate(out.trim_end().len());
        out.push('\n');
        out
    }
}

/// `noun` with its first letter upper-case, to open a sentence.
fn capitalised(noun: &str) -> String {
    let mut chars = noun.chars();
    chars.next().map(|first| first.to_uppercase().chain(chars).collect()).unwrap_or_default()
}

fn doc(out: &mut String, doc: Doc<'_>) {
    let _ = writeln!(out, "{}\n", doc.summary.trim());
    if !doc.details.trim().is_empty() {
        let _ = writeln!(out, "{}\n", doc.details.trim());
    }
    if let Some(example) = doc.example {
        let _ = writeln!(out, "Example:\n\n```\n{}\n```\n", example.trim());
    }
    let _ = writeln!(out, "Manual: {}", doc.source.trim());
}

/// The written forms, one per line, as a code block.
fn syntax(out: &mut String, forms: &[String]) {
    if !forms.is_empty() {
        let _ = writeln!(out, "```\n{}\n```\n", forms.join("\n"));
    }
}

fn facts(out: &mut String, facts: &[(&str, Option<String>)]) {
    let present: Vec<_> = facts.iter().filter_map(|(name, value)| Some((name, value.as_ref()?))).collect();
    if present.is_empty() {
        return;
    }
    for (name, value) in present {
        let _ = writeln!(out, "- {name}: {value}");
    }
    out.push('\n');
}

fn list(items: &[String]) -> Option<String> {
    (!items.is_empty()).then(|| items.join(", "))
}

fn codes_of(catalogue: &Catalogue, group: &str) -> String {
    catalogue.codes_in(group).map(|c| c.code.as_str()).collect::<Vec<_>>().join(", ")
}

fn modality(modality: Modality) -> &'static str {
    match modality {
        Modality::Modal => "modal (holds until replaced)",
        Modality::Block => "only in its block",
    }
}

fn status(status: ParameterStatus) -> &'static str {
    match status {
        ParameterStatus::Ordinary => "ordinary",
        ParameterStatus::Special => "special role",
        ParameterStatus::NotRecommended => "not recommended",
        ParameterStatus::Reserved => "reserved, must not be used",
    }
}

fn dimensional(dimensional: Dimensional) -> &'static str {
    match dimensional {
        Dimensional::Yes => "yes (carries a unit)",
        Dimensional::No => "no (a code or count)",
        Dimensional::Depends => "depends on the function in the block",
        Dimensional::Unclassified => "not classified by the manual",
    }
}

fn role(role: AddressRole) -> &'static str {
    match role {
        AddressRole::BlockNumber => "block number",
        AddressRole::Parameter => "parameter",
        AddressRole::Function => "function code",
        AddressRole::Axis => "axis",
        AddressRole::Interpolation => "interpolation parameter",
        AddressRole::Feed => "feed",
        AddressRole::Speed => "spindle speed",
        AddressRole::Tool => "tool",
        AddressRole::Offset => "tool-offset entry",
        AddressRole::LengthCompensation => "length compensation",
        AddressRole::Count => "count or dwell",
        AddressRole::Label => "subprogram, macrocycle or jump target",
        AddressRole::Auxiliary => "auxiliary function",
        AddressRole::ThreadLeadIn => "thread lead-in",
        AddressRole::BlockSkip => "block skip",
        AddressRole::ProgramNumber => "program number",
        AddressRole::ProgramEnd => "physical end",
        AddressRole::Corner => "corner chamfer or rounding",
        AddressRole::Spline => "spline parameter",
        AddressRole::Orientation => "tool orientation",
        AddressRole::Tolerance => "path tolerance",
    }
}

fn keyword_kind(kind: KeywordKind) -> &'static str {
    match kind {
        KeywordKind::Declaration => "declaration",
        KeywordKind::Type => "data type",
        KeywordKind::Literal => "literal",
        KeywordKind::Control => "control structure",
        KeywordKind::Jump => "jump",
        KeywordKind::Subprogram => "subprogram call or end",
        KeywordKind::Transformation => "kinematic transformation",
        KeywordKind::SynchronousAction => "synchronous action",
        KeywordKind::Statement => "statement",
    }
}
