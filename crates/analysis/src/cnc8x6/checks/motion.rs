//! Motion and compensation: feed before feed moves; radius compensation
//! G40/G41/G42 (the blocks it may start and end in, its plane, its entry D,
//! the control's 200-block look-ahead); length compensation `&`/D and the
//! correction-table write `G92 D`.

use nc_exec::cnc8x6::{arcs, arith::MAX_RAW};
use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{Severity, TextEdit, TextRange};

use nc_exec::known::Known;

use crate::{
    Config, Diagnostic,
    cnc8x6::checks::block::{assigns_corrections, parameter_raw},
    cnc8x6::flow::{FlowCheck, ModalState, Visit},
    diagnostic::declare_rules,
    lower::{BlockData, Value, Word},
};

declare_rules! {
    MISSING_FEED = "M401", "missing-feed", Error, "A feed move (G01, G02, G03) before any feed F was programmed.";
    COMPENSATION_OUTSIDE_LINEAR = "M402", "compensation-outside-linear-block", Error, "G40, G41 or G42 in a circular or thread block.";
    G40_WITHOUT_PLANE_MOTION = "M403", "g40-without-plane-motion", Error, "G40 in a block that does not move in the compensation plane.";
    PLANE_CHANGE_DURING_COMPENSATION = "M404", "plane-change-during-compensation", Error, "G17-G19 or G14-G16 while radius compensation is on.";
    COMPENSATION_IN_RAPID_BLOCK = "M405", "compensation-in-rapid-block", Warning, "G41 or G42 in a rapid (G00) block, or G40 there while radius compensation is on.";
    COMPENSATION_LOOKAHEAD_EXCEEDED = "M406", "compensation-lookahead-exceeded", Warning, "More than 200 blocks in a row without motion in the compensation plane while radius compensation is on.";
    RADIUS_COMPENSATION_WITHOUT_D = "M407", "radius-compensation-without-d", Warning, "G41 or G42 with no tool-offset entry D selected since the program start, or with D0.";
    LENGTH_COMPENSATION_CHANGE_ON_ARC = "M408", "length-compensation-change-on-arc", Error, "A new length compensation (`&`, or D in mode B) in a circular block.";
    LENGTH_COMPENSATION_WITHOUT_D = "M409", "length-compensation-without-d", Warning, "A non-zero `&` with no tool-offset entry D selected since the program start.";
    AMPERSAND_NOT_ALLOWED_IN_MODE = "M410", "ampersand-not-allowed-in-mode", Error, "An `&` that the length-compensation mode of machine constant 329 does not allow (a warning in mode B, which does not use `&`).";
    LENGTH_CORRECTION_OUT_OF_RANGE = "M411", "length-correction-out-of-range", Error, "A length correction R1-R4 of a `G92 D` block beyond 999.999 mm.";
    G92_CORRECTION_WITHOUT_D = "M412", "g92-correction-without-d", Error, "A G92 block that assigns correction values R0-R4 without naming the entry D to write.";
}

/// Codes whose axis words are data, not motion.
const DATA_CODES: [u32; 9] = [10, 31, 35, 36, 37, 38, 39, 92, 93];

/// The plane codes of group G1.
pub(crate) const PLANE_CODES: [u32; 6] = [17, 18, 19, 14, 15, 16];

/// How many blocks without motion in its plane radius compensation bridges
/// when it looks ahead for the next contour element.
const LOOKAHEAD_BLOCKS: usize = 200;

/// The largest length correction the offset table holds, in µm.
const MAX_LENGTH_CORRECTION: i64 = 999_999;

/// Whether the block's axis words are data (helix lead, table writes,
/// transformations) rather than motion.
pub(crate) fn data_block(visit: &Visit<'_>) -> bool {
    DATA_CODES.iter().any(|&c| visit.has_code(b'G', c))
}

/// Whether the block moves: axis words outside data blocks.
pub(crate) fn moves(visit: &Visit<'_>) -> bool {
    !data_block(visit) && axis_words(visit.block).next().is_some()
}

pub(crate) fn axis_words(block: &BlockData) -> impl Iterator<Item = &Word> {
    let catalogue = Dialect::Cnc8x6.catalogue();
    block.words.iter().filter(move |w| catalogue.role_of(w.letter) == Some(AddressRole::Axis))
}

fn moves_in_plane(visit: &Visit<'_>, axes: [u8; 2]) -> bool {
    moves(visit) && axis_words(visit.block).any(|w| axes.contains(&w.letter))
}

fn compensation_on(state: &ModalState) -> bool {
    matches!(state.g(3), Some(Some(41 | 42)))
}

/// The range that stands for a whole block: its first word.
fn block_head(visit: &Visit<'_>) -> TextRange {
    visit.block.words.first().map_or(visit.range(TextRange::default()), |w| visit.range(w.range))
}

#[derive(Default)]
pub(crate) struct Motion {
    /// Blocks in a row without motion in the compensation plane while
    /// radius compensation is on.
    off_plane: usize,
    /// The last block that moved in the compensation plane.
    last_in_plane: Option<TextRange>,
}

impl FlowCheck for Motion {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        check_feed(visit, out);
        check_compensation(visit, out);
        self.check_lookahead(visit, out);
        check_length_compensation(visit, out);
        check_correction_write(visit, out);
    }
}

fn check_feed(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(Some(motion)) = visit.after.g(0) else { return };
    if !matches!(motion, 1..=3) || !moves(visit) {
        return;
    }
    let missing = match visit.after.feed {
        Known::Is(None) => true,
        Known::Is(Some(setting)) => setting.value.scaled(3) == Some(0),
        Known::Unknown => false,
    };
    if missing {
        let range = visit
            .code_range(b'G', motion)
            .or_else(|| axis_words(visit.block).next().map(|w| visit.range(w.range)))
            .expect("a moving block has an axis word");
        out.push(Diagnostic::new(
            &MISSING_FEED,
            range,
            format!("G{motion:02} moves at the feed F, but no feed has been programmed (the reset state is F0); write F in this or an earlier block"),
        ));
    }
}

fn check_compensation(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some((code, range)) = [40, 41, 42].into_iter().find_map(|c| Some((c, visit.code_range(b'G', c)?))) else {
        if let Some(plane) = PLANE_CODES.into_iter().find(|&c| visit.has_code(b'G', c))
            && compensation_on(visit.before)
            && visit.before.g(1) != Some(Some(plane))
        {
            let range = visit.code_range(b'G', plane).expect("written in the block");
            out.push(Diagnostic::new(
                &PLANE_CHANGE_DURING_COMPENSATION,
                range,
                format!("G{plane} changes the compensation plane while radius compensation is on; cancel it with G40 in a linear block first"),
            ));
        }
        return;
    };
    let motion = visit.after.g(0).flatten();
    if let Some(bad @ (2 | 3 | 33)) = motion {
        let what = if bad == 33 { "a thread" } else { "a circular" };
        let mut diagnostic = Diagnostic::new(
            &COMPENSATION_OUTSIDE_LINEAR,
            range,
            format!(
                "G{code} in {what} block (G{bad:02}): radius compensation starts and ends only in a block with linear interpolation"
            ),
        );
        // Make the block linear: replace its G02/G03/G33, or add G01 when
        // the circular mode comes from an earlier block.
        let edit = match visit.code_range(b'G', bad) {
            Some(written) => TextEdit::replace(written, "G01"),
            None => TextEdit::replace(TextRange::empty(range.start()), "G01 "),
        };
        diagnostic =
            diagnostic.with_fix(format!("Make this a linear block (G01) so that G{code} is allowed"), vec![edit]);
        out.push(diagnostic);
        return;
    }
    let active = compensation_on(visit.before);
    // G40 without compensation on cancels nothing (`G00 G40` opens many
    // programs), so only a real cancel in a rapid block is doubtful.
    if motion == Some(0) && (code != 40 || active) {
        let what = if code == 40 { "cancels" } else { "starts" };
        out.push(Diagnostic::new(
            &COMPENSATION_IN_RAPID_BLOCK,
            range,
            format!("G{code} {what} radius compensation in a rapid block (G00): the manual allows this only in a linear-interpolation block and does not say what the control does with G00 here; program the move with G01"),
        ));
    }
    if code != 40 {
        check_radius_entry(visit, code, range, out);
        return;
    }
    if !active {
        return;
    }
    // G40 must move in the compensation plane unless machine constant 339
    // (decade 7) allows it in other blocks.
    if visit.config.machine.decade(339, 7) == 1 {
        return;
    }
    let Some(Some(plane)) = visit.before.g(1) else { return };
    let Some(axes) = arcs::compensation_plane(&visit.config.machine, plane) else { return };
    if !moves_in_plane(visit, axes) {
        out.push(Diagnostic::new(
            &G40_WITHOUT_PLANE_MOTION,
            range,
            format!(
                "G40 must be in a block that moves {} or {} (the G{plane} compensation plane); add the departure move to this block (machine constant 339 decade 7 = 1 would allow it here)",
                char::from(axes[0]),
                char::from(axes[1])
            ),
        ));
    }
}

/// G41/G42 take the tool radius from the entry D: none selected means no
/// compensation.
fn check_radius_entry(visit: &Visit<'_>, code: u32, range: TextRange, out: &mut Vec<Diagnostic>) {
    let diagnostic = match (visit.after.offset_written, visit.after.offset) {
        (Known::Is(false), _) => Diagnostic::new(
            &RADIUS_COMPENSATION_WITHOUT_D,
            range,
            format!("G{code} offsets the path by the tool radius of the offset entry D, but no D has been programmed since the program start (D is not part of the reset state); select the entry with D in this or an earlier block"),
        ),
        (_, Known::Is(Some(entry))) if entry.value.scaled(0) == Some(0) => Diagnostic::new(
            &RADIUS_COMPENSATION_WITHOUT_D,
            range,
            format!("G{code} offsets the path by the tool radius of the offset entry D, but D0 selects no entry, so the path is not compensated; select the entry with D1 to D99"),
        )
        .with_related(None, entry.range, "D0 is set here"),
        _ => return,
    };
    out.push(diagnostic);
}

impl Motion {
    /// Radius compensation bridges at most 200 blocks without motion in
    /// its plane when it looks for the next contour element.
    fn check_lookahead(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let plane = visit.after.g(1).flatten().and_then(|code| arcs::compensation_plane(&visit.config.machine, code));
        let Some(axes) = plane.filter(|_| compensation_on(visit.after)) else {
            *self = Motion::default();
            return;
        };
        if moves_in_plane(visit, axes) {
            self.off_plane = 0;
            self.last_in_plane = Some(block_head(visit));
            return;
        }
        self.off_plane += 1;
        if self.off_plane == LOOKAHEAD_BLOCKS + 1 {
            let mut diagnostic = Diagnostic::new(
                &COMPENSATION_LOOKAHEAD_EXCEEDED,
                block_head(visit),
                format!(
                    "{} blocks in a row up to this one do not move {} or {} while radius compensation is on, but the control bridges at most {LOOKAHEAD_BLOCKS} such blocks when it looks ahead for the next contour element, so the compensated path is not computed across this stretch; cancel compensation (G40) before it or move in the plane earlier",
                    self.off_plane,
                    char::from(axes[0]),
                    char::from(axes[1])
                ),
            );
            if let Some(last) = self.last_in_plane {
                diagnostic = diagnostic.with_related(None, last, "the last move in the compensation plane");
            }
            out.push(diagnostic);
        }
    }
}

/// The length-compensation mode of machine constant 329, decade 7.
#[derive(Clone, Copy, PartialEq, Eq)]
enum LengthMode {
    /// `&` digits per axis with D.
    A,
    /// D alone; `&` is not used.
    B,
    /// `&1`/`&0` switch the corrections of D.
    C,
}

fn length_mode(config: &Config) -> Option<LengthMode> {
    match config.machine.decade(329, 7) {
        0 => Some(LengthMode::A),
        1 => Some(LengthMode::B),
        // The manual prints 0 for mode C as well, evidently a misprint; 2
        // is the likely value.
        2 => Some(LengthMode::C),
        _ => None,
    }
}

/// The first word with `letter` and its value as a dimensionless address
/// reads it (a parameter gives its raw digits), if known.
fn digits_of<'a>(visit: &Visit<'a>, letter: u8) -> Option<(&'a Word, Option<i64>)> {
    let index = visit.block.words.iter().position(|w| w.letter == letter)?;
    let word = &visit.block.words[index];
    let value = match (&word.value, visit.substitutions.get(index).copied().flatten()) {
        (Some(Value::Literal(d)), _) => d.scaled(0).and_then(|v| i64::try_from(v).ok()),
        (Some(Value::Parameter { .. }), Some(s)) => Some(s.raw),
        _ => None,
    };
    Some((word, value))
}

/// A dimensionless word as written (`&0010`), or with the parameter's value.
fn written(word: &Word, value: Option<i64>) -> String {
    let letter = char::from(word.letter);
    match (&word.value, value) {
        (Some(Value::Literal(literal)), _) => format!("{letter}{literal}"),
        (_, Some(value)) => format!("{letter}{value}"),
        _ => letter.to_string(),
    }
}

fn check_length_compensation(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(mode) = length_mode(visit.config) else { return };
    if let Some((word, value)) = digits_of(visit, b'&') {
        let range = visit.range(word.range);
        match (mode, value) {
            (LengthMode::B, _) => {
                let mut diagnostic = Diagnostic::new(
                    &AMPERSAND_NOT_ALLOWED_IN_MODE,
                    range,
                    "machine constant 329 selects length-compensation mode B, which does not use `&`: D with an entry number engages its length corrections in every axis and D0 cancels them; remove `&`",
                );
                // `&` is unused rather than forbidden in mode B.
                diagnostic.severity = Severity::Warning;
                out.push(diagnostic);
            }
            (LengthMode::C, Some(value)) if value > 1 => out.push(Diagnostic::new(
                &AMPERSAND_NOT_ALLOWED_IN_MODE,
                range,
                format!("in length-compensation mode C (machine constant 329) `&` is only a switch: `&1` engages the length corrections of entry D in all axes and `&0` cancels them, so `{}` is not allowed", written(word, Some(value))),
            )),
            _ => {}
        }
        if mode != LengthMode::B && value.is_some_and(|v| v != 0) && visit.after.offset_written == Known::Is(false) {
            out.push(Diagnostic::new(
                &LENGTH_COMPENSATION_WITHOUT_D,
                range,
                format!("`{}` applies the length corrections of the offset entry D, but no D has been programmed since the program start (D is not part of the reset state); select the entry with D in this or an earlier block", written(word, value)),
            ));
        }
    }
    check_length_change_on_arc(visit, mode, out);
}

/// A new length compensation is engaged only by a linear or rapid block.
fn check_length_change_on_arc(visit: &Visit<'_>, mode: LengthMode, out: &mut Vec<Diagnostic>) {
    let Some(Some(arc @ (2 | 3))) = visit.after.g(0) else { return };
    if !moves(visit) {
        return;
    }
    let (letter, before) = match mode {
        LengthMode::B => (b'D', visit.before.offset),
        LengthMode::A | LengthMode::C => (b'&', visit.before.length),
    };
    let Some((word, Some(value))) = digits_of(visit, letter) else { return };
    let previous = match before {
        // The priority block's `&0`.
        Known::Is(None) => Some(0),
        Known::Is(Some(setting)) => setting.value.scaled(0).and_then(|v| i64::try_from(v).ok()),
        Known::Unknown => None,
    };
    if previous.is_none_or(|previous| previous == value) {
        return;
    }
    let what = match mode {
        LengthMode::B => format!("`{}` (length-compensation mode B)", written(word, Some(value))),
        LengthMode::A | LengthMode::C => format!("`{}`", written(word, Some(value))),
    };
    let mut diagnostic = Diagnostic::new(
        &LENGTH_COMPENSATION_CHANGE_ON_ARC,
        visit.range(word.range),
        format!(
            "{what} changes the length compensation in a circular block (G{arc:02}): the control engages a new length correction only in a linear (G01) or rapid (G00) block; move the change to a straight block before the arc"
        ),
    );
    if let Known::Is(Some(setting)) = before {
        diagnostic = diagnostic.with_related(None, setting.range, "the length compensation in force until here");
    }
    out.push(diagnostic);
}

/// `G92 D<n> R0=… R1=…` writes the radius (R0) and the length corrections
/// of axes 1 to 4 (R1–R4) into entry n of the tool-offset table.
fn check_correction_write(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(g92) = visit.code_range(b'G', 92) else { return };
    let unknown_code = visit
        .block
        .words
        .iter()
        .zip(visit.substitutions)
        .any(|(w, s)| w.letter == b'G' && matches!(w.value, Some(Value::Parameter { .. })) && s.is_none());
    let mut corrections = visit.block.assignments.iter().filter(|a| matches!(a.index, Some(0..=4)));
    if visit.block.word(b'D').is_none() {
        // With G53–G59 the block writes a zero-offset row and R0–R4 are
        // plain parameters; a code from an unknown parameter may be one.
        let offset_row = visit.codes.iter().any(|&(l, n, _)| l == b'G' && (53..=59).contains(&n));
        let first = corrections.next().filter(|_| !offset_row && !unknown_code && assigns_corrections(visit.block));
        if let Some(first) = first {
            out.push(
                Diagnostic::new(
                    &G92_CORRECTION_WITHOUT_D,
                    g92,
                    "G92 with R0-R4 writes correction values into the tool-offset table, but the block names no entry D to write them to; add D with the entry number (e.g. `G92 D12 R0=10.`)",
                )
                .with_related(None, visit.range(first.range), "a correction value"),
            );
        }
        return;
    }
    for assignment in corrections.filter(|a| a.index != Some(0)) {
        let Some(Value::Literal(value)) = &assignment.value else { continue };
        let Some(raw) = parameter_raw(value) else { continue };
        // Beyond a parameter's range the block checks report the value.
        if (MAX_LENGTH_CORRECTION + 1..=MAX_RAW).contains(&raw.abs()) {
            let axis = assignment.index.unwrap_or_default();
            out.push(Diagnostic::new(
                &LENGTH_CORRECTION_OUT_OF_RANGE,
                visit.range(assignment.value_range.unwrap_or(assignment.range)),
                format!("R{axis} is the length correction of axis {axis}, and the offset table holds at most ±999.999 mm; `{value}` is beyond it"),
            ));
        }
    }
}
