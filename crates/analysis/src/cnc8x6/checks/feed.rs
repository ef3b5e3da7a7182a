//! Feed and spindle speed: ranges, limits and constant cutting speed; and
//! empty blocks, which only the block before them can justify.

use ncc_catalog::Dialect;
use ncc_syntax::{TextEdit, TextRange, TextSize};

use nc_exec::known::Known;

use crate::{
    Config, Diagnostic,
    cnc8x6::checks::{
        block::{digit_overflow, parameter_raw},
        motion,
    },
    cnc8x6::flow::{FlowCheck, ModalState, Setting, Substitution, Visit, show_thousandths},
    diagnostic::declare_rules,
    lower::{BlockData, Value, Word},
};

declare_rules! {
    FEED_OUT_OF_RANGE = "F101", "feed-out-of-range", Error, "A feed per minute above the control's maximum of 90 m/min.";
    FEED_ABOVE_MACHINE_LIMIT = "F102", "feed-above-machine-limit", Warning, "A feed per minute above the machine's feed limit (`feed-limit` in ncc.toml).";
    FEED_PER_REV_EXCEEDS_MAX_VELOCITY = "F103", "feed-per-rev-exceeds-max-velocity", Warning, "A feed per revolution whose speed S × F exceeds the machine's feed limit.";
    GEAR_CHANGE_IN_CSS_BLOCK = "F104", "gear-change-in-css-block", Warning, "A gear-range change M41–M44 in a block that moves under constant cutting speed.";
    CSS_REQUIRES_VERSION_2 = "F105", "css-requires-version-2", Warning, "G76, or constant cutting speed switched on without motion, on a control with the older CSS (machine constant 580 = 00).";
    EMPTY_BLOCK = "F106", "empty-block", Info, "A block with only its number where no empty block is required.";
}

/// The control's largest feed per minute (90 m/min).
const MAX_FEED_PER_MINUTE: i64 = 90_000;

/// How the active group-G6 code makes F read.
#[derive(Clone, Copy)]
pub(crate) struct FeedMode {
    pub code: u32,
    pub per_revolution: bool,
    /// Constant cutting speed: S is a cutting speed, not a spindle speed.
    css: bool,
}

pub(crate) fn feed_mode(state: &ModalState, config: &Config) -> Option<FeedMode> {
    let code = state.g(6)??;
    // Machine constant 329 decade 3 = 1 or 3 swaps G96 and G97.
    let swapped = matches!(config.machine.decade(329, 3), 1 | 3);
    let per_revolution = match code {
        94 => false,
        95 => true,
        96 => swapped,
        97 => !swapped,
        _ => return None,
    };
    Some(FeedMode { code, per_revolution, css: matches!(code, 96 | 97) })
}

/// A feed as the control reads it: mm/min per minute, µm/rev per
/// revolution (a decimal point means thousands of these, like a parameter's
/// raw value). `None` when the format already rejects it (too-many-digits,
/// parameter-digit-overflow) or it is negative.
fn feed_value(feed: &Setting) -> Option<i64> {
    let address = Dialect::Cnc8x6.catalogue().address("F")?;
    if digit_overflow(address, &feed.value).is_some() {
        return None;
    }
    parameter_raw(&feed.value).filter(|&raw| raw >= 0)
}

/// The block's word with `letter`, with its substituted value.
fn written<'a>(visit: &Visit<'a>, letter: u8) -> Option<(&'a Word, Option<Substitution>)> {
    visit.block.words.iter().zip(visit.substitutions).find(|(w, _)| w.letter == letter).map(|(w, s)| (w, *s))
}

#[derive(Default)]
pub(crate) struct Feed {
    /// The previous block needs an empty block after it.
    empty_block_expected: bool,
    /// The program units being walked, innermost last.
    units: Vec<UnitBlocks>,
}

/// The empty blocks of one program unit, reported when the unit ends
/// unless a jump targets them (an empty block may serve as a label).
#[derive(Default)]
struct UnitBlocks {
    empty: Vec<EmptyBlock>,
    jump_targets: Vec<u64>,
    /// A jump from a parameter of unknown value may target any block.
    unknown_jump: bool,
}

struct EmptyBlock {
    number: Option<u64>,
    /// The block number, where the finding is shown.
    range: TextRange,
    /// The whole block, when removing it loses nothing (no comment).
    removal: Option<TextRange>,
}

impl FlowCheck for Feed {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        check_feed_range(visit, out);
        check_velocity(visit, out);
        check_gear_change(visit, out);
        check_css_version(visit, out);
        self.track_empty_blocks(visit);
    }

    fn end_of_unit(&mut self, _state: &ModalState, _last: Option<(TextSize, &BlockData)>, out: &mut Vec<Diagnostic>) {
        self.empty_block_expected = false;
        let Some(unit) = self.units.pop() else { return };
        if unit.unknown_jump {
            return;
        }
        for empty in unit.empty {
            if empty.number.is_some_and(|n| unit.jump_targets.contains(&n)) {
                continue;
            }
            let mut diagnostic = Diagnostic::new(
                &EMPTY_BLOCK,
                empty.range,
                "this block holds only its number and does nothing; an empty block is needed only after a thread with run-out (J) or lead-in (E) and after switching a transformation on or off, so it can be removed",
            );
            if let Some(removal) = empty.removal {
                diagnostic = diagnostic.with_fix("Remove the empty block", vec![TextEdit::replace(removal, "")]);
            }
            out.push(diagnostic);
        }
    }
}

/// F per minute against the control's maximum and the machine's limit.
fn check_feed_range(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some((word, substitution)) = written(visit, b'F') else { return };
    // In a thread block F is the lead (thread-lead-too-large).
    if visit.after.g(0) == Some(Some(33)) {
        return;
    }
    // Per revolution the maximum, 99.999 mm/rev, is the format's own.
    let Some(mode) = feed_mode(visit.after, visit.config).filter(|m| !m.per_revolution) else { return };
    let Known::Is(Some(feed)) = visit.after.feed else { return };
    let Some(per_minute) = feed_value(&feed) else { return };
    let origin = substitution.and_then(|s| s.origin);
    // A parameter written with a point has its own rule, which tells the
    // unit it was read in (feed-parameter-in-metres).
    if origin.is_some_and(|o| o.point && !o.computed) {
        return;
    }
    let limit = i64::from(visit.config.machine.feed_limit);
    let (rule, maximum) = if per_minute > MAX_FEED_PER_MINUTE {
        (&FEED_OUT_OF_RANGE, format!("the control's maximum of {MAX_FEED_PER_MINUTE} mm/min (90 m/min)"))
    } else if per_minute > limit {
        (&FEED_ABOVE_MACHINE_LIMIT, format!("this machine's maximum feed of {limit} mm/min (`feed-limit` in ncc.toml)"))
    } else {
        return;
    };
    let (shown, unit) = match &word.value {
        Some(Value::Literal(value)) if value.has_point() => {
            (format!("`F{value}`"), " (with a decimal point F is in m/min)")
        }
        Some(Value::Literal(value)) => (format!("`F{value}`"), ""),
        Some(Value::Parameter { index: Some(index), .. }) => (format!("`FR{index}`"), ""),
        _ => ("the feed".to_owned(), ""),
    };
    let mut diagnostic = Diagnostic::new(
        rule,
        visit.range(word.value_range.unwrap_or(word.range)),
        format!("under G{}, {shown} is {per_minute} mm/min{unit}: above {maximum}", mode.code),
    );
    if let Some(origin) = origin {
        diagnostic = diagnostic.with_related(None, origin.range, "the value was assigned here");
    }
    out.push(diagnostic);
}

/// Feed per revolution: the axes move at S × F, which the machine's feed
/// limit bounds (βmax = Vmax / S).
fn check_velocity(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let Some(mode) = feed_mode(visit.after, visit.config).filter(|m| m.per_revolution && !m.css) else { return };
    // F is a thread lead under G33; S is a speed limit with G76.
    if visit.after.g(0) == Some(Some(33)) || visit.has_code(b'G', 76) {
        return;
    }
    let (Known::Is(Some(feed)), Known::Is(Some(speed))) = (visit.after.feed, visit.after.speed) else { return };
    // Report where F, S or the mode is programmed, not in every block after.
    let f = visit.block.word(b'F').map(|w| visit.range(w.range));
    let s = visit.block.word(b'S').map(|w| visit.range(w.range));
    let Some(range) = f.or(s).or_else(|| visit.code_range(b'G', mode.code)) else { return };
    let Some(micrometres_per_rev) = feed_value(&feed) else { return };
    let speed_format = Dialect::Cnc8x6.catalogue().address("S");
    if speed_format.is_none_or(|address| digit_overflow(address, &speed.value).is_some()) {
        return;
    }
    let rpm = speed.value.to_f64();
    if rpm <= 0.0 {
        return;
    }
    let velocity = rpm * micrometres_per_rev as f64 / 1000.0;
    let limit = f64::from(visit.config.machine.feed_limit);
    if velocity <= limit {
        return;
    }
    let mut diagnostic = Diagnostic::new(
        &FEED_PER_REV_EXCEEDS_MAX_VELOCITY,
        range,
        format!(
            "under G{} the axes move at S × F = {} rpm × {} mm/rev = {velocity:.0} mm/min, above this machine's maximum feed of {limit} mm/min (`feed-limit` in ncc.toml); at S{} the feed may be at most {:.3} mm/rev",
            mode.code,
            speed.value,
            show_thousandths(micrometres_per_rev),
            speed.value,
            limit / rpm
        ),
    );
    if f.is_none() {
        diagnostic = diagnostic.with_related(None, feed.range, "the feed is set here");
    }
    if s.is_none() {
        diagnostic = diagnostic.with_related(None, speed.range, "the spindle speed is set here");
    }
    out.push(diagnostic);
}

fn css_active(state: &ModalState) -> bool {
    matches!(state.g(6), Some(Some(96 | 97)))
}

/// The gear range cannot change during a block, and CSS moves need it set.
fn check_gear_change(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    if !css_active(visit.after) || !motion::moves(visit) {
        return;
    }
    for &(_, code, range) in
        visit.codes.iter().filter(|&&(letter, code, _)| letter == b'M' && (41..=44).contains(&code))
    {
        out.push(Diagnostic::new(
            &GEAR_CHANGE_IN_CSS_BLOCK,
            range,
            format!("M{code} changes the gear range in a block that moves under constant cutting speed, but the range cannot change during a block; select it in an earlier block, before the CSS moves"),
        ));
    }
}

/// With the older CSS (machine constant 580 decades 1–2 = 00) CSS acts only
/// in motion blocks and there is no speed limit G76.
fn check_css_version(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    // R580 has no documented default: judge only a configured value.
    let Some(version) = visit.config.machine.known_constant(580) else { return };
    // Decades 1–2: 00 the older CSS, 01 version 2.
    if version.rem_euclid(100) != 0 {
        return;
    }
    if let Some(range) = visit.code_range(b'G', 76) {
        out.push(Diagnostic::new(
            &CSS_REQUIRES_VERSION_2,
            range,
            "G76 (spindle-speed limit) exists only in CSS version 2, but machine constant 580 = 00 selects the older CSS, which has no speed limit",
        ));
    }
    if motion::moves(visit) || !css_active(visit.after) {
        return;
    }
    for code in [96, 97] {
        if let Some(range) = visit.code_range(b'G', code) {
            out.push(Diagnostic::new(
                &CSS_REQUIRES_VERSION_2,
                range,
                format!("G{code} in a block without motion: with the older CSS (machine constant 580 = 00) constant cutting speed acts only in motion blocks; write G{code} in the first cutting move"),
            ));
        }
    }
}

impl Feed {
    fn track_empty_blocks(&mut self, visit: &Visit<'_>) {
        let block = visit.block;
        if self.units.is_empty() || visit.has_code(b'G', 79) {
            self.units.push(UnitBlocks::default());
        }
        let Some(unit) = self.units.last_mut() else { return };
        if let Some(number) = block.number.filter(|_| block.is_empty() && !self.empty_block_expected) {
            unit.empty.push(EmptyBlock {
                number: number.value,
                range: visit.range(number.range),
                removal: block.comments.is_empty().then(|| visit.range(TextRange::up_to(block.len))),
            });
        }
        if visit.has_code(b'G', 73) {
            match jump_target(visit) {
                Some(target) => unit.jump_targets.push(target),
                None => unit.unknown_jump = true,
            }
        }
        self.empty_block_expected = justifies_empty_block(visit);
    }
}

/// The block number a G73 jumps to.
fn jump_target(visit: &Visit<'_>) -> Option<u64> {
    let (word, substitution) = written(visit, b'L')?;
    match (&word.value, substitution) {
        (Some(Value::Literal(value)), _) => value.scaled(0).and_then(|v| u64::try_from(v).ok()),
        (Some(Value::Parameter { .. }), Some(s)) => u64::try_from(s.raw).ok(),
        _ => None,
    }
}

/// Whether the next block may be empty for a reason: after a thread with
/// run-out or lead-in and after a transformation code (switching one on or
/// off) the control needs one, and a placeholder unit has one as its body
/// (`N1 G79 L88` / `N2` / `N3 G70`).
fn justifies_empty_block(visit: &Visit<'_>) -> bool {
    let catalogue = Dialect::Cnc8x6.catalogue();
    let thread_with_runout =
        visit.after.g(0) == Some(Some(33)) && (visit.block.word(b'J').is_some() || visit.block.word(b'E').is_some());
    let transformation = visit
        .codes
        .iter()
        .any(|&(letter, code, _)| letter == b'G' && catalogue.group_of('G', code).is_some_and(|g| g.id == "G11"));
    thread_with_runout || transformation || visit.has_code(b'G', 79)
}
