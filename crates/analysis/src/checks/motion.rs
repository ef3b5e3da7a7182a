//! Motion and radius compensation: feed before feed moves, G40/G41/G42 only
//! in linear blocks.

use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{TextEdit, TextRange};

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    flow::{FlowCheck, Known, Visit},
    lower::BlockData,
};

declare_rules! {
    MISSING_FEED = "M401", "missing-feed", Error, "A feed move (G01, G02, G03) before any feed F was programmed.";
    COMPENSATION_OUTSIDE_LINEAR = "M402", "compensation-outside-linear-block", Error, "G40, G41 or G42 in a circular or thread block.";
    G40_WITHOUT_PLANE_MOTION = "M403", "g40-without-plane-motion", Error, "G40 in a block that does not move in the compensation plane.";
    PLANE_CHANGE_DURING_COMPENSATION = "M404", "plane-change-during-compensation", Error, "G17-G19 or G14-G16 while radius compensation is on.";
}

/// Codes whose axis words are data, not motion.
const DATA_CODES: [u32; 9] = [10, 31, 35, 36, 37, 38, 39, 92, 93];

/// Whether the block moves: axis words outside data blocks.
pub(crate) fn moves(visit: &Visit<'_>) -> bool {
    !DATA_CODES.iter().any(|&c| visit.has_code(b'G', c)) && axis_words(visit.block).next().is_some()
}

fn axis_words(block: &BlockData) -> impl Iterator<Item = &crate::lower::Word> {
    let catalogue = Dialect::Cnc8x6.catalogue();
    block.words.iter().filter(move |w| catalogue.role_of(w.letter) == Some(AddressRole::Axis))
}

/// The two axes of the compensation plane of G17/G18/G19 (G14–G16 use the
/// configured fourth axis).
fn plane_axes(code: u32, fourth: u8) -> Option<[u8; 2]> {
    Some(match code {
        17 => [b'X', b'Y'],
        18 => [b'Z', b'X'],
        19 => [b'Y', b'Z'],
        14 => [b'Z', fourth],
        15 => [b'Y', fourth],
        16 => [fourth, b'X'],
        _ => return None,
    })
}

#[derive(Default)]
pub(crate) struct Motion;

impl FlowCheck for Motion {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        check_feed(visit, out);
        check_compensation(visit, out);
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
        if let Some(plane) = [17, 18, 19, 14, 15, 16].into_iter().find(|&c| visit.has_code(b'G', c)) {
            let active = matches!(visit.before.g(3), Some(Some(41 | 42)));
            if active && visit.before.g(1) != Some(Some(plane)) {
                let range = visit.code_range(b'G', plane).expect("written in the block");
                out.push(Diagnostic::new(
                    &PLANE_CHANGE_DURING_COMPENSATION,
                    range,
                    format!("G{plane} changes the compensation plane while radius compensation is on; cancel it with G40 in a linear block first"),
                ));
            }
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
    if code != 40 || !matches!(visit.before.g(3), Some(Some(41 | 42))) {
        return;
    }
    // G40 must move in the compensation plane unless machine constant 339
    // (decade 7) allows it in other blocks.
    if visit.config.machine.decade(339, 7) == 1 {
        return;
    }
    let fourth = visit.config.machine.axes.get(3).copied().unwrap_or(b'U');
    let Some(Some(plane)) = visit.before.g(1) else { return };
    let Some(axes) = plane_axes(plane, fourth) else { return };
    let in_plane = moves(visit) && axis_words(visit.block).any(|w| axes.contains(&w.letter));
    if !in_plane {
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
