//! Tool-nose radius compensation (lathe manual §9 rules 22–26, §7.1
//! (001:955-967, 1043-1047)).

use nc_exec::known::Known;

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    haas_lathe::{
        checks::Out,
        model::FileModel,
        walk::{COMPENSATION, Kind, Visit, ends_program},
    },
};

declare_rules! {
    COMPENSATION_START_ON_ARC = "L022", "compensation-start-on-arc", Error, "Tool-nose compensation G41/G42 starting on an arc: it must start on a G00/G01 move.";
    COMPENSATION_END_ON_ARC = "L023", "compensation-end-on-arc", Error, "Tool-nose compensation cancelled (G40) on an arc: it must end on a G00/G01 move.";
    UNCOMPENSATED_CONTOUR = "L024", "uncompensated-contour", Info, "An arc or taper cut with tool-nose compensation off (G40).";
    COMPENSATION_LEFT_ON = "L025", "compensation-left-on", Warning, "Tool-nose compensation G41/G42 still on at a tool change or at the program's end.";
    CONTOUR_COMPENSATION_OPEN = "L026", "contour-compensation-open", Warning, "Tool-nose compensation switched on inside a contour P..Q and still on after its Q block.";
}

pub(crate) fn visit(visit: &Visit<'_>, out: &mut Out) {
    switch(visit, out);
    uncompensated(visit, out);
    left_on(visit, out);
}

fn on(code: Known<Option<u32>>) -> bool {
    matches!(code, Known::Is(Some(41 | 42)))
}

/// Rules 22 and 23: the move that starts or cancels the compensation is
/// the one in the block that switches it, or the next. The digest's rule 22
/// names cycles too, but the seed writes G90 and G94 with G41/42 (001:1463,
/// 1471): only arcs are flagged.
fn switch(visit: &Visit<'_>, out: &mut Out) {
    let Kind::Move(Known::Is(arc @ (2 | 3))) = visit.kind else { return };
    let before = visit.before.code(COMPENSATION);
    let after = visit.after.code(COMPENSATION);
    let switched_here = before != Known::Unknown && before != after;
    let (switch, code) = if switched_here {
        (visit.index, after)
    } else if let Some(block) = visit.before.compensation_change {
        (block, before)
    } else {
        return;
    };
    let Known::Is(Some(code)) = code else { return };
    let switch_range = visit.file.code_range(switch, b'G', code);
    let (rule, what, verb) = if on(Known::Is(Some(code))) {
        (&COMPENSATION_START_ON_ARC, "start", "starts")
    } else {
        (&COMPENSATION_END_ON_ARC, "cancellation", "cancels")
    };
    let message = format!(
        "the compensation's {what} (G{code}) falls on this G{arc:02} arc: the control {verb} it only on a straight G00/G01 move"
    );
    let at = if visit.writes(arc) { visit.code_range(arc) } else { switch_range };
    let mut diagnostic = Diagnostic::new(rule, at, message);
    if switch != visit.index {
        diagnostic = diagnostic.with_related(None, switch_range, format!("G{code} here"));
    }
    out.push(diagnostic);
}

/// Rule 24: arcs and tapers want the compensation; a hint once a program,
/// not at every move.
fn uncompensated(visit: &Visit<'_>, out: &mut Out) {
    let off = |code| code == Known::Is(Some(40));
    // The move that cancels the compensation is rule 23's.
    if !off(visit.before.code(COMPENSATION))
        || !off(visit.after.code(COMPENSATION))
        || visit.before.compensation_change.is_some()
    {
        return;
    }
    let what = match visit.kind {
        Kind::Move(Known::Is(code @ (2 | 3))) => format!("this G{code:02} arc"),
        Kind::Move(Known::Is(1)) => {
            let moved = |from: Known<f64>, to: Known<f64>| matches!((from, to), (Known::Is(a), Known::Is(b)) if (a - b).abs() > 1e-9);
            if !(moved(visit.before.x, visit.after.x) && moved(visit.before.z, visit.after.z)) {
                return;
            }
            "this taper".to_owned()
        }
        _ => return,
    };
    let at = visit.block.words.iter().find(|w| matches!(w.letter, b'X' | b'Z' | b'U' | b'W'));
    let Some(at) = at else { return };
    let message = format!(
        "{what} is cut with tool-nose compensation off (G40): the nose radius leaves arcs and tapers off size; program G41/G42 for contours"
    );
    out.once(visit, Diagnostic::new(&UNCOMPENSATED_CONTOUR, visit.range(at), message));
}

/// Rule 25: the compensation is cancelled before a tool change and the end.
fn left_on(visit: &Visit<'_>, out: &mut Out) {
    let code = visit.before.code(COMPENSATION);
    if visit.contour.is_some() || !on(code) || visit.writes(40) {
        return;
    }
    let Known::Is(Some(code)) = code else { return };
    let (word, at) = if let Some(tool) = visit.block.word(b'T') {
        (visit.range(tool), "the tool change")
    } else if ends_program(visit.block) {
        let end = if visit.block.has_code(b'M', 30) { 30 } else { 2 };
        (visit.file.code_range(visit.index, b'M', end), "the program's end")
    } else {
        return;
    };
    let message =
        format!("tool-nose compensation G{code} is still on at {at}: cancel it with G40 on a G00/G01 move before");
    out.push(Diagnostic::new(&COMPENSATION_LEFT_ON, word, message));
}

/// Rule 26: every example cancels the compensation it switches on in a
/// contour in the contour's Q block (001:1817, 1887, 2019, 2199, 1580).
pub(crate) fn check(file: &FileModel) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let mut seen = Vec::new();
    for contour in file.model.contours() {
        if seen.contains(&contour.blocks) {
            continue;
        }
        seen.push(contour.blocks.clone());
        let mut last = None;
        for index in contour.blocks.clone() {
            for (code, word) in file.block(index).code_words(b'G').filter(|&(code, _)| (40..=42).contains(&code)) {
                last = Some((code, index, word));
            }
        }
        let Some((code @ (41 | 42), index, word)) = last else { continue };
        let q = *contour.blocks.end();
        let message = format!(
            "G{code} switches tool-nose compensation on in the contour, and no G40 cancels it by the Q block: the cycle returns to its start point compensated"
        );
        let diagnostic = Diagnostic::new(&CONTOUR_COMPENSATION_OPEN, file.number_range(q), message).with_related(
            None,
            file.in_file(index, word.range),
            format!("G{code}"),
        );
        out.push(diagnostic);
    }
    out
}
