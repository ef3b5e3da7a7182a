//! Rules on the names a program uses (digest §6 rules 61 and 62, and the
//! declared, unused and undeclared names), one pass over the blocks.
//!
//! A name the file does not declare may be global user data or a macro of
//! the machine (L30's `VAC_POLE`, 004:3112), so it is a warning, once per
//! name, and `[sinumerik] globals` in `ncc.toml` declares such names.
//! Names the control knows need no declaration: addresses and axes (`X1`,
//! `A3`), keywords, codes, predefined functions, system variables (`$…`)
//! and R parameters.

use std::collections::{HashMap, HashSet};

use nc_exec::sinumerik::lower::{Callee, ExprKind, JumpTarget, PlaceKind, StatementKind};
use ncc_catalog::{Catalogue, Dialect};
use ncc_syntax::{TextRange, TextSize};

use crate::lowered::Watched;
use crate::{
    Config, Diagnostic,
    db::Db,
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{each_expr, statement_exprs, written_places},
        model::FileModel,
    },
};

declare_rules! {
    INCONSISTENT_CASE = "K061", "inconsistent-case", Hint, "A name written in different cases (`VAR_I`, `var_i`): the control does not mind, a reader may.";
    NAMED_LIKE_ADDRESS = "K062", "named-like-address", Warning, "A variable or parameter named like an address or axis (`X`, `C`, `H`).";
    UNDECLARED_NAME = "K101", "undeclared-name", Warning, "A name the file does not declare and the control does not know; names declared outside the file go in `[sinumerik] globals`.";
    UNUSED_VARIABLE = "K102", "unused-variable", Hint, "A variable declared by DEF and never read.", unnecessary;
    UNUSED_LABEL = "K103", "unused-label", Hint, "A label no jump names.", unnecessary;
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Use {
    Declared,
    Read,
    Written,
}

/// A name where it is written in the file.
struct Occurrence<'a> {
    /// Upper case.
    name: &'a str,
    range: TextRange,
    used: Use,
}

pub(crate) fn check(db: &dyn Db, file: &FileModel, text: &str, config: &Config) -> Vec<Diagnostic> {
    let catalogue = Dialect::Sinumerik.catalogue();
    let occurrences = occurrences(db, file, text);
    let mut declared: HashSet<&str> = file.model.labels.keys().map(String::as_str).collect();
    declared.extend(file.model.definitions.iter().map(|d| d.declared.name.as_str()));
    for proc in &file.model.procs {
        declared.extend(proc.declaration.parameters.iter().filter_map(|p| p.name.as_deref()));
    }
    for block in file.blocks(db) {
        for statement in &block.statements {
            if let StatementKind::Define { name, .. } = &statement.kind {
                declared.insert(name);
            }
        }
    }
    let mut out = Vec::new();
    // Each name is looked up once: the catalogue's lists are searched.
    let mut decided: HashSet<&str> = HashSet::new();
    for occurrence in occurrences.iter().filter(|o| o.used != Use::Declared) {
        let name = occurrence.name;
        if declared.contains(name) || !decided.insert(name) || known(catalogue, config, name) {
            continue;
        }
        let message = format!(
            "{name} is not declared in this file: declare it with DEF, or, if it is declared outside the file (global user data), list it in `[sinumerik] globals` of ncc.toml"
        );
        out.push(Diagnostic::new(&UNDECLARED_NAME, occurrence.range, message));
    }
    named_like_address(catalogue, config, &occurrences, &mut out);
    unused_variables(file, &occurrences, &mut out);
    unused_labels(db, file, &mut out);
    cases(text, &occurrences, &mut out);
    out
}

/// Whether the control knows `name` without a declaration.
fn known(catalogue: &Catalogue, config: &Config, name: &str) -> bool {
    let letters = name.trim_end_matches(|c: char| c.is_ascii_digit());
    config.sinumerik.is_global(name)
        || catalogue.address(name).is_some()
        || (!letters.is_empty() && catalogue.address(letters).is_some())
        || catalogue.keyword(name).is_some()
        || catalogue.code_named(name).is_some()
        || catalogue.function(name).is_some()
        || matches!(name.as_bytes(), [letter] if config.machine.is_axis(*letter))
}

/// The range of `name` written at `start`, if the text has it there.
fn name_at(text: &str, start: TextSize, name: &str) -> Option<TextRange> {
    let range = TextRange::at(start, TextSize::of(name));
    text.get(std::ops::Range::<usize>::from(range)).filter(|written| written.eq_ignore_ascii_case(name)).map(|_| range)
}

/// Every declaration, read and write of a user name, in file order.
fn occurrences<'a>(db: &'a dyn Db, file: &'a FileModel, text: &str) -> Vec<Occurrence<'a>> {
    let mut all = Vec::new();
    for (index, block) in file.blocks(db).enumerate() {
        let mut push = |name: &'a str, start: TextSize, used: Use| {
            let start = file.in_file(index, TextRange::empty(start)).start();
            if let Some(range) = name_at(text, start, name) {
                all.push(Occurrence { name, range, used });
            }
        };
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::Def(def) => {
                    for declared in &def.names {
                        push(&declared.name, declared.range.start(), Use::Declared);
                    }
                }
                StatementKind::Proc(proc) => {
                    for parameter in &proc.parameters {
                        let Some(name) = &parameter.name else { continue };
                        // The name ends the parameter, before its dimensions.
                        let written = file.in_file(index, parameter.range);
                        let Some(slice) = text.get(std::ops::Range::<usize>::from(written)) else { continue };
                        let head = slice.split('[').next().unwrap_or_default().trim_end();
                        let start = parameter.range.start() + TextSize::of(head) - TextSize::of(name.as_str());
                        push(name, start, Use::Declared);
                    }
                }
                _ => {}
            }
            written_places(statement, &mut |place, statement| {
                if place.kind != PlaceKind::User {
                    return;
                }
                let mut start = statement.range.start();
                if let StatementKind::For { .. } = statement.kind {
                    // `FOR name = …`: the name follows the keyword.
                    let written = file.in_file(index, statement.range);
                    let slice = text.get(std::ops::Range::<usize>::from(written)).unwrap_or_default();
                    let after = slice.get(3..).unwrap_or_default();
                    start += TextSize::of(&slice[..slice.len() - after.trim_start().len()]);
                }
                push(&place.name, start, Use::Written);
            });
            statement_exprs(statement, &mut |expr| {
                each_expr(expr, &mut |inner| {
                    if let ExprKind::Name(place) = &inner.kind
                        && place.kind == PlaceKind::User
                    {
                        push(&place.name, inner.range.start(), Use::Read);
                    }
                });
            });
        }
    }
    all
}

/// Rule 62: declarations named like an address or an axis.
fn named_like_address(
    catalogue: &Catalogue,
    config: &Config,
    occurrences: &[Occurrence<'_>],
    out: &mut Vec<Diagnostic>,
) {
    for occurrence in occurrences.iter().filter(|o| o.used == Use::Declared) {
        let name = occurrence.name;
        let axis = matches!(name.as_bytes(), [letter] if config.machine.is_axis(*letter));
        if catalogue.address(name).is_none() && !axis {
            continue;
        }
        let message = format!(
            "{name} is also the name of an address: `{name}=…` in a block writes the variable, never the address, and readers take it for the address; choose another name"
        );
        out.push(Diagnostic::new(&NAMED_LIKE_ADDRESS, occurrence.range, message));
    }
}

fn unused_variables(file: &FileModel, occurrences: &[Occurrence<'_>], out: &mut Vec<Diagnostic>) {
    let read: HashSet<&str> = occurrences.iter().filter(|o| o.used == Use::Read).map(|o| o.name).collect();
    // Variables of a scope (NCK, CHAN) are read by other programs.
    let local: HashSet<&str> =
        file.model.definitions.iter().filter(|d| d.scope.is_none()).map(|d| d.declared.name.as_str()).collect();
    for occurrence in occurrences.iter().filter(|o| o.used == Use::Declared) {
        if local.contains(occurrence.name) && !read.contains(occurrence.name) {
            let message = format!("{} is never read", occurrence.name);
            out.push(Diagnostic::new(&UNUSED_VARIABLE, occurrence.range, message));
        }
    }
}

/// Labels no jump names; none when a jump computes its target, which
/// may name any of them.
fn unused_labels(db: &dyn Db, file: &FileModel, out: &mut Vec<Diagnostic>) {
    let mut named: HashSet<&str> = HashSet::new();
    for site in &file.model.jumps {
        match &site.jump.target {
            Some(JumpTarget::Label(label)) => {
                named.insert(label);
            }
            Some(JumpTarget::Computed(_)) => return,
            _ => {}
        }
    }
    for block in file.blocks(db) {
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::RepeatSection { start, end, .. } => {
                    named.extend(std::iter::once(start).chain(end).map(String::as_str))
                }
                StatementKind::Call(call) if matches!(call.callee, Callee::Indirect { section: Some(_), .. }) => return,
                _ => {}
            }
        }
    }
    for (label, blocks) in &file.model.labels {
        if named.contains(label.as_str()) {
            continue;
        }
        for &index in blocks {
            let Some(written) = &file.block(index).label else { continue };
            let message = format!("no jump names the label {label}");
            out.push(Diagnostic::new(&UNUSED_LABEL, file.in_file(index, written.range), message));
        }
    }
}

/// Rule 61: the first place each other spelling of a name stands.
fn cases(text: &str, occurrences: &[Occurrence<'_>], out: &mut Vec<Diagnostic>) {
    let mut first: HashMap<&str, (&str, TextRange)> = HashMap::new();
    let mut reported: HashSet<(&str, &str)> = HashSet::new();
    for occurrence in occurrences {
        let written = &text[std::ops::Range::<usize>::from(occurrence.range)];
        let &mut (spelling, range) = first.entry(occurrence.name).or_insert((written, occurrence.range));
        if spelling != written && reported.insert((occurrence.name, written)) {
            let message = format!("{written} is written {spelling} elsewhere: one spelling reads more easily");
            out.push(Diagnostic::new(&INCONSISTENT_CASE, occurrence.range, message).with_related(
                None,
                range,
                spelling.to_owned(),
            ));
        }
    }
}
