//! Geometry of circular and helical blocks: both end coordinates of the
//! arc's plane and no third axis, the end point on the circle, the centre
//! refinement E, the helix lead G10 before G09, and G98 ending a helix.
//!
//! The arc's plane is given by the two axes written in the block (G17–G19
//! choose only the radius-compensation plane); I is the centre offset along
//! the plane's first axis and J along the second, both from the start point.

use nc_exec::{
    arc::{OffCircle, circle_through},
    cnc8x6::arcs::{self, InvalidRefinement},
};
use ncc_syntax::{TextEdit, TextRange};

use nc_exec::known::Known;

use crate::{
    Diagnostic,
    cnc8x6::checks::motion,
    cnc8x6::flow::{FlowCheck, Visit, thousandths},
    diagnostic::declare_rules,
    lower::Word,
};

declare_rules! {
    ARC_MISSING_END_COORDINATE = "M413", "arc-missing-end-coordinate", Error, "A circular block that does not program both end coordinates of its plane.";
    ARC_EXTRA_AXIS = "M414", "arc-extra-axis", Warning, "A circular block with a third axis and no helix.";
    ARC_END_NOT_ON_CIRCLE = "M415", "arc-end-not-on-circle", Error, "An arc whose end point is not on the circle through its start point around the centre I, J (beyond 1 µm or machine constant 55).";
    INVALID_ARC_REFINEMENT = "M416", "invalid-arc-refinement", Error, "A centre refinement E whose eighth digit is neither 0 (refine I) nor 1 (refine J).";
    HELIX_WITHOUT_PITCH = "M417", "helix-without-pitch", Warning, "G09 with no helix lead programmed by G10 since the program start.";
    G98_NOT_ALONE = "B218", "g98-not-alone", Error, "G98 ending a helix shares its block with other words.";
}

/// Margin for the rounding of square roots, in µm.
const ROUNDING: f64 = 1e-6;

#[derive(Default)]
pub(crate) struct Geometry;

impl FlowCheck for Geometry {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        check_helix_lead(visit, out);
        check_helix_end(visit, out);
        let Some(arc) = Arc::of(visit) else { return };
        let refinement = check_refinement(visit, out);
        match arc.axes.len() {
            0 | 1 => out.push(missing_end_coordinate(visit, &arc)),
            2 => out.extend(end_off_circle(visit, &arc, refinement)),
            _ => {
                if arc.helix == Some(false) {
                    out.extend(extra_axis(visit, &arc));
                }
            }
        }
    }
}

/// A circular block.
struct Arc<'a> {
    /// G02 or G03.
    code: u32,
    /// The axis words, one per axis, without the axis a helix drives.
    axes: Vec<&'a Word>,
    /// Whether a helix (G09) is on, if known.
    helix: Option<bool>,
}

impl<'a> Arc<'a> {
    /// The block as an arc: G02/G03 in force and an end coordinate or a
    /// centre word written, outside data blocks and fixed cycles.
    fn of(visit: &Visit<'a>) -> Option<Arc<'a>> {
        let Some(Some(code @ (2 | 3))) = visit.after.g(0) else { return None };
        let no_cycle = matches!(visit.after.g(8), Some(None | Some(80)));
        if !no_cycle || motion::data_block(visit) {
            return None;
        }
        let helix = visit.after.g(2).map(|code| code == Some(9));
        let lead = match (helix, visit.after.helix_lead_axis) {
            (Some(true), Known::Is(Some(axis))) => Some(axis),
            _ => None,
        };
        let mut axes: Vec<&Word> = Vec::new();
        for word in motion::axis_words(visit.block) {
            if Some(word.letter) != lead && axes.iter().all(|w| w.letter != word.letter) {
                axes.push(word);
            }
        }
        let centre = visit.block.word(b'I').is_some() || visit.block.word(b'J').is_some();
        (!axes.is_empty() || centre).then_some(Arc { code, axes, helix })
    }

    /// Where to point at the arc: its G02/G03, else its first coordinate.
    fn range(&self, visit: &Visit<'_>) -> Option<TextRange> {
        visit.code_range(b'G', self.code).or_else(|| self.axes.first().map(|w| visit.range(w.range)))
    }
}

fn check_helix_lead(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(range) = visit.code_range(b'G', 9) else { return };
    if visit.after.helix_lead_axis == Known::Is(None) {
        out.push(Diagnostic::new(
            &HELIX_WITHOUT_PITCH,
            range,
            "G09 moves the helix's axis by the lead programmed with G10, but no lead has been programmed since the program start; program it in an earlier block, e.g. `N10 Z1.05 G10` for 1.05 mm per turn on Z",
        ));
    }
}

/// The manual wants the G98 that ends a helix in a block of its own; as
/// the standard block joining after other modes G98 may share its block.
fn check_helix_end(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(range) = visit.code_range(b'G', 98) else { return };
    let block = visit.block;
    if visit.before.has_g(2, 9) && block.body_words().count() + block.assignments.len() > 1 {
        out.push(Diagnostic::new(
            &G98_NOT_ALONE,
            range,
            "G98 ends the helix here and must be programmed in a block of its own; move the other words to the next block",
        ));
    }
}

/// The centre refinement E of a circular block (written by the control's
/// preprocessor for arcs from imprecise CAD data).
enum Refinement {
    Absent,
    Of(arcs::Refinement),
    /// Unknown, or invalid and reported.
    Unusable,
}

fn check_refinement(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) -> Refinement {
    let Some(index) = visit.block.words.iter().position(|w| w.letter == b'E') else { return Refinement::Absent };
    let word = &visit.block.words[index];
    let Some(raw) = thousandths(word, visit.substitutions.get(index).copied().flatten()) else {
        return Refinement::Unusable;
    };
    match arcs::refinement(raw) {
        Ok(refinement) => Refinement::Of(refinement),
        Err(InvalidRefinement { selector }) => {
            let found =
                if selector > 9 { "E has more than eight digits".to_owned() } else { format!("here it is {selector}") };
            out.push(Diagnostic::new(
                &INVALID_ARC_REFINEMENT,
                visit.range(word.value_range.unwrap_or(word.range)),
                format!("the eighth digit of a centre refinement E picks the word it corrects, 0 for I or 1 for J (`E2.054` adds 2.054 µm to I, `E-10006.992` subtracts 6.992 µm from J), but {found}; the control cannot apply it"),
            ));
            Refinement::Unusable
        }
    }
}

fn missing_end_coordinate(visit: &Visit<'_>, arc: &Arc<'_>) -> Diagnostic {
    let modal = if visit.has_code(b'G', arc.code) {
        String::new()
    } else {
        format!(
            " (the block is circular because G{:02} is in force; write G01 if it is meant to be straight)",
            arc.code
        )
    };
    let Some(&written) = arc.axes.first() else {
        let centre = visit.block.words.iter().find(|w| matches!(w.letter, b'I' | b'J'));
        let range = visit.code_range(b'G', arc.code).or(centre.map(|w| visit.range(w.range))).unwrap_or_default();
        return Diagnostic::new(
            &ARC_MISSING_END_COORDINATE,
            range,
            format!(
                "this arc has a centre but no end point: a circular block programs both end coordinates of its plane, even for a full circle{modal}"
            ),
        );
    };
    let letter = char::from(written.letter);
    let range = visit.range(written.range);
    let Some((other, value)) = missing_coordinate(visit, written.letter) else {
        return Diagnostic::new(
            &ARC_MISSING_END_COORDINATE,
            range,
            format!(
                "this arc programs only {letter}: a circular block programs both end coordinates of its plane, even one that does not change{modal}"
            ),
        );
    };
    let other = char::from(other);
    Diagnostic::new(
        &ARC_MISSING_END_COORDINATE,
        range,
        format!("this arc programs only {letter}: a circular block programs both end coordinates of its plane, even one that does not change; add {other}{value}{modal}"),
    )
    .with_fix(
        format!("Add {other}{value} ({other} does not change)"),
        vec![TextEdit::replace(TextRange::empty(range.end()), format!(" {other}{value}"))],
    )
}

/// The coordinate an arc that writes only `letter` leaves out, taking the
/// compensation plane as the arc's plane, with the value that keeps it
/// where it is.
fn missing_coordinate(visit: &Visit<'_>, letter: u8) -> Option<(u8, String)> {
    let plane = arcs::compensation_plane(&visit.config.machine, visit.after.g(1)??)?;
    let other = match plane {
        [first, second] if first == letter => second,
        [first, second] if second == letter => first,
        _ => return None,
    };
    let value = match visit.after.g(9)? {
        Some(91) => "0".to_owned(),
        _ => millimetres(visit.after.position(other)?),
    };
    Some((other, value))
}

/// µm as a coordinate in mm with a decimal point (`250000` → `250.`).
fn millimetres(micrometres: i64) -> String {
    let sign = if micrometres < 0 { "-" } else { "" };
    let magnitude = micrometres.unsigned_abs();
    let fraction = format!("{:03}", magnitude % 1000);
    format!("{sign}{}.{}", magnitude / 1000, fraction.trim_end_matches('0'))
}

fn extra_axis(visit: &Visit<'_>, arc: &Arc<'_>) -> Option<Diagnostic> {
    // The axis outside the compensation plane when both of its axes are
    // written, else the third one written.
    let plane = visit.after.g(1).flatten().and_then(|code| arcs::compensation_plane(&visit.config.machine, code));
    let in_plane = |letter: u8| plane.is_some_and(|plane| plane.contains(&letter));
    let both = arc.axes.iter().filter(|w| in_plane(w.letter)).count() == 2;
    let extra = arc.axes.iter().find(|w| both && !in_plane(w.letter)).or(arc.axes.get(2))?;
    let letter = char::from(extra.letter);
    Some(Diagnostic::new(
        &ARC_EXTRA_AXIS,
        visit.range(extra.range),
        format!(
            "{letter} is a third axis in this circular block, but circular interpolation runs in a plane of two axes; move {letter} in a block of its own, or program a helix (its lead with G10, then G09)"
        ),
    ))
}

/// The end point must lie on the circle through the start point around the
/// centre I, J (incremental from the start).
fn end_off_circle(visit: &Visit<'_>, arc: &Arc<'_>, refinement: Refinement) -> Option<Diagnostic> {
    // K has no meaning in an arc; a block with one was written for another
    // control, and its centre is anybody's guess.
    if visit.block.word(b'K').is_some() {
        return None;
    }
    let [a, b] = arc.axes.as_slice() else { return None };
    let written = [a.letter, b.letter];
    let [first, second] = arcs::arc_plane(&visit.config.machine, written[0], written[1])?;
    let start = [visit.before.position(first)?, visit.before.position(second)?];
    let end = [visit.after.position(first)?, visit.after.position(second)?];
    let mut centre = [centre_offset(visit, b'I')? as f64, centre_offset(visit, b'J')? as f64];
    match refinement {
        Refinement::Absent => {}
        Refinement::Of(arcs::Refinement { word, amount }) => centre[word] += amount as f64 / 1000.0,
        Refinement::Unusable => return None,
    }
    // X may be a diameter (G74); whether I/J then are too the manual does
    // not say. A finding must hold for every reading the state allows:
    // (factor on X positions, factor on the X centre offset).
    let x = [first, second].iter().position(|&axis| axis == b'X');
    let readings: &[(f64, f64)] = match (x, visit.after.g(10)) {
        (None, _) | (_, Some(Some(75))) => &[(1.0, 1.0)],
        (_, Some(Some(74))) => &[(0.5, 1.0), (0.5, 0.5)],
        _ => &[(1.0, 1.0), (0.5, 1.0), (0.5, 0.5)],
    };
    // In µm, as the positions.
    let tolerance = visit.config.machine.arc_tolerance() * 1000.0;
    let circle = |&(position, offset): &(f64, f64)| {
        let along = |axis: usize, value: f64, factor: f64| if Some(axis) == x { value * factor } else { value };
        let c = [along(0, centre[0], offset), along(1, centre[1], offset)];
        let s = [along(0, start[0] as f64, position), along(1, start[1] as f64, position)];
        let e = [along(0, end[0] as f64, position), along(1, end[1] as f64, position)];
        // The direction does not matter to whether the end is on the circle.
        circle_through(s, e, [s[0] + c[0], s[1] + c[1]], true, tolerance + ROUNDING)
    };
    if readings.iter().map(circle).any(|circle| circle.is_ok()) {
        return None;
    }
    let OffCircle { start_radius: from_start, end_radius: from_end } = circle(&readings[0]).err()?;
    Some(Diagnostic::new(
        &ARC_END_NOT_ON_CIRCLE,
        arc.range(visit)?,
        format!(
            "the end point is not on the arc's circle: the centre (I along {}, J along {}, from the start point) is {:.3} mm from the start but {:.3} mm from the end, and the two may differ by at most {:.3} mm (1 µm unless machine constant 55 widens it), so the control stops with error 7.56 \"end point does not lie on the circle\"; correct the end point or the centre",
            char::from(first),
            char::from(second),
            from_start / 1000.0,
            from_end / 1000.0,
            tolerance / 1000.0
        ),
    ))
}

/// A centre offset in µm: 0 when not written (a zero component may be
/// left out), `None` when unknown.
fn centre_offset(visit: &Visit<'_>, letter: u8) -> Option<i64> {
    let Some(index) = visit.block.words.iter().position(|w| w.letter == letter) else { return Some(0) };
    thousandths(&visit.block.words[index], visit.substitutions.get(index).copied().flatten())
}
