//! The program as a whole (lathe manual §9 rules 53, 55–57).

use nc_exec::{haas_lathe::program::Blocks, known::Known};

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    haas_lathe::{
        checks::Out,
        model::FileModel,
        walk::{Kind, Setting, Visit, axis_words, ends_program},
    },
};

declare_rules! {
    NO_PROGRAM_END = "L053", "no-program-end", Warning, "A program without M30 or M02 (or M99, for a subprogram).";
    CSS_WITHOUT_LIMIT = "L055", "css-without-limit", Warning, "Constant surface speed G96 before any spindle speed limit G50 S.";
    FEED_BEFORE_WORK_OFFSET = "L056", "feed-before-work-offset", Info, "Feed moves before any work offset or G53 was programmed: the power-on G54 applies.";
    NO_MOTION_CODE_AT_START = "L057", "no-motion-code-at-start", Warning, "A move before any G00–G03 was written: G01, in force at power-on, makes it a feed move.";
}

/// Rule 53 (001:293, 312): every program ends; a subprogram with M99.
pub(crate) fn check(file: &FileModel) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let blocks = file.blocks();
    for program in &file.model.programs {
        // The ends are marked blocks.
        let mut ends = blocks.marked(program.blocks.clone()).map(|index| file.block(index));
        if ends.any(|block| ends_program(block) || block.has_code(b'M', 99)) {
            continue;
        }
        let Some(last) = program.blocks.clone().rev().find(|&index| file.block(index).has_content()) else { continue };
        let block = file.block(last);
        let range = block.program.as_ref().map(|o| o.range).or(block.words.first().map(|w| w.range));
        let message = "the program has no end: M30 ends it and goes back to its start, M02 ends it (a subprogram returns with M99)";
        out.push(Diagnostic::new(&NO_PROGRAM_END, file.in_file(last, range.unwrap_or_default()), message));
    }
    out
}

pub(crate) fn visit(visit: &Visit<'_>, out: &mut Out) {
    if visit.writes(96) && visit.after.speed_limit == Setting::Unset {
        let message = "G96 without a speed limit G50 S before it: near the centre constant surface speed drives the spindle up to the machine's maximum (every example programs G50 S first)";
        out.push(Diagnostic::new(&CSS_WITHOUT_LIMIT, visit.code_range(96), message));
    }
    let feeds = matches!(visit.kind, Kind::Move(Known::Is(1..=3 | 32)) | Kind::Cycle(_) | Kind::Drill);
    if feeds && visit.contour.is_none() && visit.after.origin_chosen == Known::Is(false) {
        let message = "this is the program's first feed move and no work offset (G54–G59, G110–G129) or G53 was programmed: it runs in G54, the power-on default";
        out.once(visit, Diagnostic::new(&FEED_BEFORE_WORK_OFFSET, first_word(visit), message));
    }
    let moves = matches!(visit.kind, Kind::Move(_)) || (visit.writes(53) && axis_words(visit.block));
    if moves && visit.after.motion_written == Known::Is(false) {
        let message = if visit.writes(53) {
            "G53 without G00 before any motion code was written: G01, in force at power-on, would make it a feed move (whether the control moves G53 at rapid the manual does not say)"
        } else {
            "no motion code has been written yet: G01, in force at power-on, makes this a feed move; write G00 or G01"
        };
        out.once(visit, Diagnostic::new(&NO_MOTION_CODE_AT_START, first_word(visit), message));
    }
}

/// The block's first word's range, else its start.
fn first_word(visit: &Visit<'_>) -> ncc_syntax::TextRange {
    let word = visit.block.words.iter().find(|w| w.letter != b'N');
    visit.file.in_file(visit.index, word.map_or_else(Default::default, |w| w.range))
}
