//! Coordinate transformations (G31, G34–G39) and zero offsets.
//!
//! Group G11 holds two mechanisms. The recalculations G34–G37 (mirroring,
//! scaling, independent offset) are written in blocks of their own. The
//! transformations G38, G39 (planar) and G31 (spatial) each have three
//! actions: a setting block (axes and angles), activation (the code alone)
//! and deactivation (`I0` alone); the check follows each one's state in run
//! order.

use std::cmp::Ordering;

use ncc_catalog::{AddressRole, Dialect, Modality};
use ncc_syntax::TextRange;

use crate::{
    Diagnostic,
    cnc8x6::checks::{block, motion},
    cnc8x6::flow::{FlowCheck, Visit},
    diagnostic::declare_rules,
    lower::{Value, Word},
};

declare_rules! {
    ZERO_OFFSET_WRITE_WITHOUT_AXES = "X701", "zero-offset-write-without-axes", Warning, "G92 or G93 without axis words, which writes nothing into the zero-offset table.";
    COORDINATE_TRANSFORM_NOT_ALONE = "X702", "coordinate-transform-not-alone", Error, "G35, G36 or G37 in a block with other functions.";
    INVALID_SCALE_FACTOR = "X703", "invalid-scale-factor", Error, "G36 with a scale factor or denominator of zero.";
    INVALID_SCALE_AXES = "X704", "invalid-scale-axes", Warning, "G36 with axes other than the first coordinate, or the first and second.";
    INVALID_TRANSFORMATION_PARAMETERS = "X705", "invalid-transformation-parameters", Error, "A G38/G39 setting without exactly two axes and I, or a G31 setting without three axes and I, J, K.";
    TRANSFORMATION_SETTING_WITH_MOTION = "X706", "transformation-setting-with-motion", Error, "A G31, G38 or G39 setting block with a motion code.";
    INVALID_ANGLE_DIVISOR = "X707", "invalid-angle-divisor", Error, "An angle divisor E of zero or less in a G31, G38 or G39 block.";
    AMBIGUOUS_TRANSFORMATION_DEACTIVATION = "X708", "ambiguous-transformation-deactivation", Warning, "G31, G38 or G39 with I0 and axis words: a zero angle or a deactivation.";
    TRANSFORM_DURING_COMPENSATION = "X709", "transform-during-compensation", Warning, "G34 to G37 while radius compensation G41/G42 is on.";
    TRANSFORMATION_SET_WHILE_ACTIVE = "X710", "transformation-set-while-active", Error, "A transformation's parameters set while it is active.";
    AXIS_IN_TWO_TRANSFORMATIONS = "X711", "axis-in-two-transformations", Error, "An axis in two transformations at the same time.";
    MISSING_EMPTY_BLOCK_AFTER_TRANSFORMATION = "X712", "missing-empty-block-after-transformation", Warning, "A motion block right after a transformation is activated or deactivated.";
    TRANSFORMATION_NOT_SET = "X713", "transformation-not-set", Warning, "A transformation activated with no setting block earlier in the program.";
    NO_ZERO_OFFSET_BEFORE_MOTION = "X714", "no-zero-offset-before-motion", Info, "The program moves before it selects the zero offset (G53 to G57) it uses later.";
}

/// The transformations of chapter 14: their code and how many axes a
/// setting block names (the angle addresses come from the catalogue).
const TRANSFORMATIONS: [(u32, usize); 3] = [(38, 2), (39, 2), (31, 3)];

/// What the control knows of one transformation, as far as the walk has
/// seen it (an unknown history leaves everything empty: nothing reported).
#[derive(Debug, Default, Clone)]
struct Transformation {
    /// No setting block has run since the program start.
    never_set: bool,
    /// The axes of the last setting block, with the words that name them.
    axes: Vec<(u8, TextRange)>,
    /// The transformation takes its axes: set or activated, and not
    /// deactivated since.
    holds_axes: bool,
    /// Where it was activated, while it is known to be active.
    active: Option<TextRange>,
}

/// The zero offset at the program start, until the program selects one.
#[derive(Debug, Default, Clone, Copy)]
enum ZeroOffset {
    /// Programmed, or not known.
    #[default]
    Settled,
    /// Neither moved nor programmed one yet.
    NotYet,
    /// Moved first, here, in the priority offset.
    MovedFirst(TextRange),
}

/// What a G31/G38/G39 block does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Action {
    Set,
    /// Axis words with `I0`: setting a zero angle, or deactivating.
    SetOrDeactivate,
    Activate,
    Deactivate,
    /// `I` from a parameter whose value is not known.
    Unknown,
}

#[derive(Default)]
pub(crate) struct Transformations {
    /// The previous block was walked from the program start.
    from_start: bool,
    transformations: [Transformation; 3],
    /// Where G41/G42 was programmed, while compensation is on.
    compensation: Option<TextRange>,
    zero_offset: ZeroOffset,
    /// The previous block activated or deactivated a transformation: its
    /// code, where it is written and whether it activated.
    needs_empty_block: Option<(u32, TextRange, bool)>,
}

impl FlowCheck for Transformations {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        self.follow_history(visit);
        if has_unknown_code(visit) {
            // It may be any offset or transformation function, and may make
            // the axis words data instead of motion.
            self.forget();
            return;
        }
        self.check_empty_block(visit, out);
        self.check_zero_offset_before_motion(visit, out);
        check_offset_write(visit, out);
        let mut group_11 = visit.codes.iter().filter(|&&(l, n, _)| l == b'G' && in_group(n, "G11"));
        // Two codes of group 11 in one block are a group conflict already;
        // what the block means is then unclear.
        if let (Some(&(_, code, range)), None) = (group_11.next(), group_11.next()) {
            match TRANSFORMATIONS.iter().position(|&(c, _)| c == code) {
                Some(index) => self.transformation_block(visit, index, range, out),
                None => self.recalculation_block(visit, code, range, out),
            }
        }
        for &(letter, number, range) in visit.codes {
            match (letter, number) {
                (b'G', 41 | 42) => self.compensation = Some(range),
                (b'G', 40) => self.compensation = None,
                _ => {}
            }
        }
        if visit.has_code(b'G', 72) {
            // The macrocycle runs unseen by the checks.
            self.forget();
        }
    }
}

impl Transformations {
    /// Starts from the program start, or from an unknown history when the
    /// walk enters a unit from an unknown state or loses track (an unknown
    /// call).
    fn follow_history(&mut self, visit: &Visit<'_>) {
        let from_start = visit.params.from_start;
        if from_start && !self.from_start {
            self.forget();
            self.zero_offset = ZeroOffset::NotYet;
            for transformation in &mut self.transformations {
                transformation.never_set = true;
            }
        } else if !from_start && (self.from_start || visit.block.has_code(b'G', 79)) {
            self.forget();
        }
        self.from_start = from_start;
    }

    fn forget(&mut self) {
        *self = Transformations { from_start: self.from_start, ..Transformations::default() };
    }

    fn check_empty_block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let Some((code, at, activated)) = self.needs_empty_block.take() else { return };
        if !motion::moves(visit) {
            return;
        }
        let head = visit.block.words.first().map_or(visit.range(TextRange::default()), |w| visit.range(w.range));
        let action = if activated { "activating" } else { "deactivating" };
        out.push(
            Diagnostic::new(
                &MISSING_EMPTY_BLOCK_AFTER_TRANSFORMATION,
                head,
                format!("after {action} G{code} the control must first take over the recomputed positions: insert an empty block (only its number) before this motion"),
            )
            .with_related(None, at, format!("G{code} {} here", if activated { "activated" } else { "deactivated" })),
        );
    }

    /// A program that relies on the priority offset throughout is
    /// consistent; one that selects an offset only after it has moved ran
    /// its first moves in another coordinate system.
    fn check_zero_offset_before_motion(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let mut offsets = visit.codes.iter().filter(|&&(l, n, _)| l == b'G' && in_group(n, "G5"));
        match self.zero_offset {
            ZeroOffset::Settled => {}
            ZeroOffset::NotYet if offsets.next().is_some() => self.zero_offset = ZeroOffset::Settled,
            ZeroOffset::NotYet => {
                if motion::moves(visit) {
                    let first_axis = axis_words(visit).next().map(|w| visit.range(w.range));
                    if let Some(range) = motion_code(visit).or(first_axis) {
                        self.zero_offset = ZeroOffset::MovedFirst(range);
                    }
                }
            }
            ZeroOffset::MovedFirst(first_move) => {
                // G92/G93 name the table row they write, which need not be
                // a selection; G58/G59 hold for their block only.
                let writes_table = visit.has_code(b'G', 92) || visit.has_code(b'G', 93);
                let catalogue = Dialect::Cnc8x6.catalogue();
                let modal = |n: u32| catalogue.code('G', n).is_some_and(|c| c.modality == Modality::Modal);
                let Some(&(_, code, at)) = offsets.find(|&&(_, n, _)| modal(n)).filter(|_| !writes_table) else {
                    return;
                };
                self.zero_offset = ZeroOffset::Settled;
                out.push(
                    Diagnostic::new(
                        &NO_ZERO_OFFSET_BEFORE_MOTION,
                        first_move,
                        format!("the program moves before it selects its zero offset G{code}, so this move runs in the priority offset (G53, or what the machine's priority block sets); program G{code} before the first move"),
                    )
                    .with_related(None, at, format!("G{code} selected here")),
                );
            }
        }
    }

    /// G34–G37: alone in their block, valid G36 factors, compensation off.
    fn recalculation_block(&self, visit: &Visit<'_>, code: u32, code_range: TextRange, out: &mut Vec<Diagnostic>) {
        if code != 34 {
            check_alone(visit, code, code_range, out);
        }
        if code == 36 {
            check_scale(visit, out);
        }
        if let Some(Some(compensation @ (41 | 42))) = visit.before.g(3) {
            let mut diagnostic = Diagnostic::new(
                &TRANSFORM_DURING_COMPENSATION,
                code_range,
                format!(
                    "G{code} while radius compensation G{compensation} is on: change mirroring, scaling and offsets with compensation off (G40 first), or the contour around this block is wrong"
                ),
            );
            if let Some(at) = self.compensation {
                diagnostic = diagnostic.with_related(None, at, format!("G{compensation} switched on here"));
            }
            out.push(diagnostic);
        }
    }

    /// G38, G39, G31: one of setting, activation or deactivation.
    fn transformation_block(
        &mut self,
        visit: &Visit<'_>,
        index: usize,
        code_range: TextRange,
        out: &mut Vec<Diagnostic>,
    ) {
        let (code, _) = TRANSFORMATIONS[index];
        let words: Vec<(&Word, Option<Ordering>)> = signed_words(visit).collect();
        let axes: Vec<&Word> = words.iter().map(|&(w, _)| w).filter(|w| is_axis(w.letter)).collect();
        let angle = words.iter().find(|(w, _)| w.letter == b'I');
        check_divisor(code, &words, visit, out);
        let other_settings = !axes.is_empty() || words.iter().any(|(w, _)| matches!(w.letter, b'J' | b'K' | b'E'));
        let action = match angle {
            Some((i, Some(Ordering::Equal))) if !axes.is_empty() => {
                out.push(Diagnostic::new(
                    &AMBIGUOUS_TRANSFORMATION_DEACTIVATION,
                    visit.range(i.range),
                    format!("G{code} with axis words and I0 may set a 0° angle or deactivate the transformation; to deactivate write `G{code} I0` in a block of its own"),
                ));
                Action::SetOrDeactivate
            }
            _ if other_settings => Action::Set,
            None => Action::Activate,
            Some((_, Some(Ordering::Equal))) => Action::Deactivate,
            Some((_, Some(_))) => Action::Set,
            Some((_, None)) => Action::Unknown,
        };
        match action {
            Action::Set | Action::SetOrDeactivate => {
                check_parameters(visit, index, code_range, &words, &axes, out);
                if let Some(motion) = motion_code(visit) {
                    out.push(Diagnostic::new(
                        &TRANSFORMATION_SETTING_WITH_MOTION,
                        motion,
                        format!("a block that sets the G{code} parameters must not move: program the motion in a block of its own"),
                    ));
                }
                let transformation = &self.transformations[index];
                if let (Action::Set, Some(at)) = (action, transformation.active) {
                    out.push(
                        Diagnostic::new(
                            &TRANSFORMATION_SET_WHILE_ACTIVE,
                            code_range,
                            format!("G{code} is active, so its parameters cannot be set: deactivate it first with `G{code} I0` followed by an empty block"),
                        )
                        .with_related(None, at, format!("G{code} activated here")),
                    );
                }
                if action == Action::Set {
                    let named: Vec<(u8, TextRange)> = axes.iter().map(|w| (w.letter, visit.range(w.range))).collect();
                    for &(letter, range) in &named {
                        self.check_axis_free(index, letter, range, "", out);
                    }
                    let transformation = &mut self.transformations[index];
                    transformation.axes = named;
                    transformation.holds_axes = true;
                    transformation.never_set = false;
                } else {
                    // Set or deactivated: what it holds is no longer known.
                    self.transformations[index] = Transformation::default();
                }
            }
            Action::Activate => {
                let transformation = &self.transformations[index];
                if transformation.never_set {
                    out.push(Diagnostic::new(
                        &TRANSFORMATION_NOT_SET,
                        code_range,
                        format!("G{code} activates the transformation, but no block earlier in the program sets its parameters, so it runs with whatever values the control kept; set them first (G{code} with the axes and angles)"),
                    ));
                }
                // After a deactivation it takes its axes again.
                if !transformation.holds_axes {
                    let letters: Vec<u8> = transformation.axes.iter().map(|&(letter, _)| letter).collect();
                    let activation = format!(" (G{code} takes it again when activated)");
                    for letter in letters {
                        self.check_axis_free(index, letter, code_range, &activation, out);
                    }
                }
                let transformation = &mut self.transformations[index];
                transformation.active = Some(code_range);
                transformation.holds_axes = true;
                self.needs_empty_block = Some((code, code_range, true));
            }
            Action::Deactivate => {
                let transformation = &mut self.transformations[index];
                transformation.active = None;
                transformation.holds_axes = false;
                self.needs_empty_block = Some((code, code_range, false));
            }
            Action::Unknown => self.transformations[index] = Transformation::default(),
        }
    }

    /// Reports `letter` when another transformation holds it.
    fn check_axis_free(&self, index: usize, letter: u8, range: TextRange, why: &str, out: &mut Vec<Diagnostic>) {
        let (code, _) = TRANSFORMATIONS[index];
        for (other, transformation) in
            self.transformations.iter().enumerate().filter(|&(i, t)| i != index && t.holds_axes)
        {
            let Some(&(_, at)) = transformation.axes.iter().find(|&&(l, _)| l == letter) else { continue };
            let (other_code, _) = TRANSFORMATIONS[other];
            let axis = char::from(letter);
            out.push(
                Diagnostic::new(
                    &AXIS_IN_TWO_TRANSFORMATIONS,
                    range,
                    format!("{axis} already belongs to the G{other_code} transformation and may be in only one at a time{why}: deactivate G{other_code} (`G{other_code} I0`) first, or use another axis for G{code}"),
                )
                .with_related(None, at, format!("{axis} set for G{other_code} here")),
            );
        }
    }
}

/// G92/G93 write the axes written in the block; without any they do
/// nothing (`G92 D..` and G92 with corrections R0–R4 write the tool-offset
/// table instead, which `g92-correction-without-d` checks).
fn check_offset_write(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    if axis_words(visit).next().is_some() {
        return;
    }
    for code in [92, 93] {
        let Some(range) = visit.code_range(b'G', code) else { continue };
        if code == 92 && (visit.block.word(b'D').is_some() || block::assigns_corrections(visit.block)) {
            continue;
        }
        let message = if code == 92 {
            "G92 without axis words writes nothing into the zero-offset table: add the axes and their offsets, e.g. `G55 G92 X100. Y50.`"
        } else {
            "G93 without axis words sets no zero offset: add the axes whose zero is set from the current position, e.g. `G55 G93 X0 Y0`"
        };
        out.push(Diagnostic::new(&ZERO_OFFSET_WRITE_WITHOUT_AXES, range, message));
    }
}

/// G35–G37 are written in a block of their own, with only their axes.
fn check_alone(visit: &Visit<'_>, code: u32, code_range: TextRange, out: &mut Vec<Diagnostic>) {
    let others: Vec<&Word> =
        visit.block.body_words().filter(|w| !is_axis(w.letter) && visit.range(w.range) != code_range).collect();
    let Some(first) = others.first() else { return };
    let list: Vec<String> = others.iter().map(|w| word_text(w)).collect();
    out.push(Diagnostic::new(
        &COORDINATE_TRANSFORM_NOT_ALONE,
        visit.range(first.range),
        format!(
            "G{code} must be programmed in a block of its own, with nothing but its axes: move {} to another block",
            list.join(" ")
        ),
    ));
}

/// G36 takes the scale under the first coordinate, or a fraction of the
/// first over the second; neither may be zero. The coordinates are the
/// machine's first two axes (X and Y, or X and Z on a lathe).
fn check_scale(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let machine_axes = &visit.config.machine.axes;
    let (Some(&first), Some(&second)) = (machine_axes.first(), machine_axes.get(1)) else { return };
    let (first, second) = (char::from(first), char::from(second));
    let words: Vec<(&Word, Option<Ordering>)> = signed_words(visit).filter(|(w, _)| is_axis(w.letter)).collect();
    let has = |axis: char| words.iter().any(|(w, _)| char::from(w.letter) == axis);
    let misplaced = words.iter().find(|(w, _)| {
        let axis = char::from(w.letter);
        !(axis == first || axis == second) || (axis == second && !has(first))
    });
    if let Some((word, _)) = misplaced {
        out.push(Diagnostic::new(
            &INVALID_SCALE_AXES,
            visit.range(word.range),
            format!("G36 takes the scale under {first} (`G36 {first}1.27`) or as the fraction {first}/{second} (`G36 {first}1.54 {second}5.28`); what `{}` means here is not defined", char::from(word.letter)),
        ));
    }
    for (word, sign) in &words {
        let axis = char::from(word.letter);
        if *sign != Some(Ordering::Equal) || !(axis == first || axis == second) {
            continue;
        }
        let what = if axis == second && has(first) { "the denominator of the scale" } else { "the scale factor" };
        out.push(Diagnostic::new(
            &INVALID_SCALE_FACTOR,
            visit.range(word.value_range.unwrap_or(word.range)),
            format!(
                "{axis}0 makes {what} zero; write the factor, e.g. `G36 {first}0.5`, or `G36` alone to cancel scaling"
            ),
        ));
    }
}

/// A setting block names as many axes as the transformation has and every
/// angle address it takes (I; I, J, K for G31), and no other.
fn check_parameters(
    visit: &Visit<'_>,
    index: usize,
    code_range: TextRange,
    words: &[(&Word, Option<Ordering>)],
    axes: &[&Word],
    out: &mut Vec<Diagnostic>,
) {
    let (code, count) = TRANSFORMATIONS[index];
    let catalogue = Dialect::Cnc8x6.catalogue();
    let angles: Vec<u8> = catalogue
        .code('G', code)
        .map(|c| c.allows.iter().filter_map(|a| a.bytes().next()).filter(|&l| is_angle(l)).collect())
        .unwrap_or_default();
    let kind = if count == 2 { "planar" } else { "spatial" };
    if axes.len() != count {
        let range = axes.get(count).map_or(code_range, |w| visit.range(w.range));
        out.push(Diagnostic::new(
            &INVALID_TRANSFORMATION_PARAMETERS,
            range,
            format!("a G{code} setting block names exactly {count} axes (the offsets of the axes in the {kind} transformation); this one has {}", axes.len()),
        ));
    }
    let missing: Vec<String> = angles
        .iter()
        .filter(|&&l| !words.iter().any(|(w, _)| w.letter == l))
        .map(|&l| char::from(l).to_string())
        .collect();
    if !missing.is_empty() {
        let all: Vec<String> = angles.iter().map(|&l| char::from(l).to_string()).collect();
        out.push(Diagnostic::new(
            &INVALID_TRANSFORMATION_PARAMETERS,
            code_range,
            format!(
                "a G{code} setting block needs the rotation angle{} {}: {} missing",
                if all.len() > 1 { "s" } else { "" },
                all.join(", "),
                missing.join(", ")
            ),
        ));
    }
    for (word, _) in words.iter().filter(|(w, _)| is_angle(w.letter) && !angles.contains(&w.letter)) {
        out.push(Diagnostic::new(
            &INVALID_TRANSFORMATION_PARAMETERS,
            visit.range(word.range),
            format!(
                "G{code} takes its angle in I only; {} is not a parameter of a {kind} transformation",
                char::from(word.letter)
            ),
        ));
    }
}

/// E divides the angles of a G31/G38/G39 block and must be positive.
fn check_divisor(code: u32, words: &[(&Word, Option<Ordering>)], visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    for (word, sign) in words.iter().filter(|(w, _)| w.letter == b'E') {
        if matches!(sign, Some(Ordering::Equal | Ordering::Less)) {
            out.push(Diagnostic::new(
                &INVALID_ANGLE_DIVISOR,
                visit.range(word.value_range.unwrap_or(word.range)),
                format!("in a G{code} block E divides the angles and must be positive (E100 gives the angles in 1/100000°); leave E out for thousandths of a degree"),
            ));
        }
    }
}

/// The block's words with how each value compares with zero, where known
/// (a literal, or a parameter with a known value).
fn signed_words<'a>(visit: &'a Visit<'_>) -> impl Iterator<Item = (&'a Word, Option<Ordering>)> {
    visit.block.words.iter().zip(visit.substitutions).map(|(word, substitution)| {
        let sign = match (&word.value, substitution) {
            (Some(Value::Literal(value)), _) => value.to_f64().partial_cmp(&0.0),
            (Some(Value::Parameter { .. }), Some(substitution)) => Some(substitution.raw.cmp(&0)),
            _ => None,
        };
        (word, sign)
    })
}

/// The motion code (group G0) written in the block.
fn motion_code(visit: &Visit<'_>) -> Option<TextRange> {
    visit.codes.iter().find(|&&(l, n, _)| l == b'G' && in_group(n, "G0")).map(|&(_, _, range)| range)
}

/// A G code taken from a parameter whose value is not known.
fn has_unknown_code(visit: &Visit<'_>) -> bool {
    visit.block.words.iter().zip(visit.substitutions).any(|(word, substitution)| {
        word.letter == b'G' && matches!(word.value, Some(Value::Parameter { .. })) && substitution.is_none()
    })
}

fn axis_words<'a>(visit: &'a Visit<'_>) -> impl Iterator<Item = &'a Word> {
    visit.block.words.iter().filter(|w| is_axis(w.letter))
}

fn is_axis(letter: u8) -> bool {
    Dialect::Cnc8x6.catalogue().role_of(letter) == Some(AddressRole::Axis)
}

/// I, J, K: the angles of a transformation.
fn is_angle(letter: u8) -> bool {
    Dialect::Cnc8x6.catalogue().role_of(letter) == Some(AddressRole::Interpolation)
}

/// Whether G `code` belongs to the catalogue's group `group`.
fn in_group(code: u32, group: &str) -> bool {
    Dialect::Cnc8x6.catalogue().group_of('G', code).is_some_and(|g| g.id == group)
}

/// A word as the programmer wrote it (`G01`, `F100`, `XR12`).
fn word_text(word: &Word) -> String {
    let letter = char::from(word.letter);
    match &word.value {
        Some(Value::Literal(value)) => format!("{letter}{value}"),
        Some(Value::Parameter { negative, index: Some(index), .. }) => {
            format!("{letter}{}R{index}", if *negative { "-" } else { "" })
        }
        _ => letter.to_string(),
    }
}
