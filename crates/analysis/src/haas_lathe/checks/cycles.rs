//! Threading and drilling cycles in the walk (lathe manual §9 rules
//! 46–48, 50).

use nc_exec::known::Known;

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    haas_lathe::{
        checks::Out,
        walk::{DRILLING, Kind, SPEED_MODE, Setting, THREAD_CHAMFER, Visit},
    },
};

declare_rules! {
    THREAD_WITHOUT_PITCH = "L046", "thread-without-pitch", Error, "Threading (G32, G76, G92) before any pitch F or E was programmed.";
    THREAD_UNDER_CSS = "L047", "thread-under-css", Warning, "Threading under constant surface speed G96.";
    THREAD_CHAMFER_SHORTENS = "L048", "thread-chamfer-shortens", Info, "G76/G92 with the thread chamfer M23 on: the thread is shorter than Z by the chamfer.";
    DRILLING_REPEATS = "L050", "drilling-repeats", Info, "A block that moves while a drilling cycle is in force, so the cycle drills again there.";
}

/// The threading codes of rule 46: F (or E) is their pitch.
pub(crate) const THREADING: [u32; 3] = [32, 76, 92];

pub(crate) fn visit(visit: &Visit<'_>, out: &mut Out) {
    thread(visit, out);
    drilling(visit, out);
}

/// Rules 46–48.
fn thread(visit: &Visit<'_>, out: &mut Out) {
    let code = match visit.kind {
        Kind::Move(Known::Is(code)) | Kind::Cycle(code) if THREADING.contains(&code) => code,
        _ => return,
    };
    let at =
        if visit.writes(code) { visit.code_range(code) } else { visit.file.in_file(visit.index, Default::default()) };
    if visit.after.feed == Setting::Unset {
        let message = format!(
            "G{code} cuts a thread, but no pitch F (or E in inches) has been programmed since the program started"
        );
        out.once(visit, Diagnostic::new(&THREAD_WITHOUT_PITCH, at, message));
    }
    if !visit.writes(code) {
        return;
    }
    if visit.after.is(SPEED_MODE, 96) {
        let message = format!(
            "G{code} threads under G96: the spindle speed follows the diameter, so passes at different depths turn at different speeds; the manual's examples thread under G97"
        );
        out.push(Diagnostic::new(&THREAD_UNDER_CSS, at, message));
    }
    if code != 32 && visit.after.is(THREAD_CHAMFER, 23) {
        let message = format!(
            "M23 is on: G{code} ends the thread with a chamfer of Setting 95 × F at the angle of Setting 96, and the full thread stops short of Z by that much"
        );
        out.push(Diagnostic::new(&THREAD_CHAMFER_SHORTENS, at, message));
    }
}

/// Rule 50: a drilling cycle runs again at every block with X, Z or C
/// (001:1077-1078), except with L0 (001:1081-1082).
fn drilling(visit: &Visit<'_>, out: &mut Out) {
    if visit.kind != Kind::Drill {
        return;
    }
    let Known::Is(Some(cycle)) = visit.after.code(DRILLING) else { return };
    if visit.writes(cycle) || visit.block.word(b'L').is_some_and(|l| visit.after.number(l) == Known::Is(0.0)) {
        return;
    }
    let Some(word) = visit.block.words.iter().find(|w| matches!(w.letter, b'X' | b'Z' | b'U' | b'W' | b'C')) else {
        return;
    };
    let message = format!(
        "the G{cycle} cycle in force drills again here: it runs at every block with X, Z or C until G80, G00 or G01"
    );
    out.push(Diagnostic::new(&DRILLING_REPEATS, visit.range(word), message));
}
