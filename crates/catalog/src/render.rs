//! Hover and `ncc explain` text: Markdown rendered from the entries.
//!
//! The same text serves the terminal and the editor, so it is plain
//! Markdown that reads well unrendered.

use std::fmt::Write;

use crate::{
    AddressRole, Catalogue, Dimensional, Documented, Flavour, Item, Modality, ParameterOverview, ParameterStatus,
    schema::Doc,
};

impl Item<'_> {
    /// A one-line heading: `G41 — Radius compensation left`.
    pub fn heading(&self, catalogue: &Catalogue) -> String {
        match *self {
            Item::Group(group) => format!("Group {} — {}", group.id, group.title),
            Item::Code(code) => format!("{} — {}", code.code, code.title),
            Item::UnlistedCode { letter, number, group } => {
                format!("{letter}{number:02} — machine-defined function (group {})", group.id)
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
                    ],
                );
                doc(&mut out, code.doc());
            }
            Item::UnlistedCode { group, .. } => {
                let _ = writeln!(
                    out,
                    "The manual does not define this code; it belongs to group {} ({}), whose functions the machine builder defines in the PLC program.\n",
                    group.id, group.title
                );
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
                                format!("allowed (e.g. `{}{}1`)", address.letter, catalogue.parameters.written)
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
    }
}
