//! Rules on motion and technology over the walk's modal state (digest §6
//! rules 16, 18, 19, 20, 22, 26, 27, 29, 31, 32, 48, 52, 67, 70, 75, 76,
//! 77, 78 and 81).
//!
//! Assumptions, where the digest is silent:
//! - Rules 18 and 26 report the first block of a stretch, not every block
//!   of it: the cause is one.
//! - Rule 26 counts M5 and M19 (positioned) as a spindle that stands, and
//!   leaves out measuring moves (`MEAS`, `MEAW`), which the probe makes
//!   with the spindle still.
//! - Rule 22 reads "at full feed" as at the feed of the cut in X or Y
//!   that follows the plunge: of several steps down in a row, the last
//!   enters the material. It is opt-in: whether the plunge enters the
//!   stock is not known (the thesis's L26 plunges beside the part), nor
//!   whether the tool cuts at its centre.
//! - Rule 27 is opt-in: dry cutting and coolant through M functions of
//!   the machine builder are common. It reads the catalogue's coolant
//!   group (M7, M8 on; M9 off).
//! - Rule 31 asks a main program to write at least one of tool radius
//!   compensation (G40), a work offset (G500, G54 …) and the dimensions
//!   (G90/G91) before its first move, as the thesis's safe block does
//!   (004:493-501); a call before the first move may write them. It is
//!   opt-in: the thesis's reason, modes surviving M30 (004:574-577), is
//!   ISO's, and a Sinumerik puts its groups back to their reset values at
//!   the end of a program (Siemens documentation, machine data MD20150).
//! - Rule 32 reports blocks after an end or an unconditional jump that no
//!   jump, repeated section or structure leads to, once per run of them.
//! - Rule 48 cannot see the caller: it warns where the subprogram itself
//!   put continuous-path mode in force, and not under SAVE, which gives
//!   the caller its modes back and does not go with RET (rule 47).
//! - Rule 70 reads a plunge as a feed move down in Z alone, and a turn as a
//!   rotary axis (A, B, C) or orientation word (A2 …, A3 …) whose value the
//!   block changes; whether the tool is in the material is not known.
//! - Rule 75 compares the largest change of a rotary axis or orientation
//!   angle (A, B, C, A2, B2, C2) with the block's path length, above
//!   [`ORIENTATION_RATE_DEG_PER_MM`]; a block that turns without moving
//!   the path is left out.
//! - Rule 76 takes points within [`SAME_POINT_MM`] for the same point.
//! - Rule 77 calls a G1 move short below [`SHORT_MOVE_MM`] and a run long
//!   from [`LONG_RUN`] such moves on; a move whose end or start the walk
//!   does not know ends the run.
//! - Rule 78 calls heavy what the control computes between two feed moves
//!   in continuous-path mode: a loop with no move in its body, or
//!   [`HEAVY_STATEMENTS`] statements or more that do not move (file order).
//! - Rule 81 counts M functions other than the stops and ends (M0, M1,
//!   M2, M17, M30), MSG, WRITE and STOPRE as the blocks that break the
//!   path (digest: inferred).

use nc_exec::{
    arc::centre_by_radius,
    known::Known,
    sinumerik::{
        lower::{Callee, ProgramEnd, Statement, StatementKind, WordValue, is_axis},
        modes::groups::{COOLANT, DIMENSIONS, MOTION, SPINDLE, TOOL_RADIUS, WORK_OFFSETS},
    },
};
use ncc_catalog::{Catalogue, Dialect};
use ncc_syntax::{TextEdit, TextRange};

use crate::{
    Diagnostic,
    diagnostic::declare_rules,
    sinumerik::{
        checks::visit::{g_number, is_transformation, word_is},
        model::FileModel,
        walk::{FOLLOWED, PATH_AXES, RadiusArc, SAME_POINT_MM, Step},
    },
};

declare_rules! {
    RAPID_PLUNGE_WITH_XY = "K016", "rapid-xy-and-z-down", Warning, "A G0 move that lowers Z while it moves X or Y: approach in X and Y first, then in Z.";
    MISSING_FEED = "K018", "no-feed-programmed", Error, "A feed move (G1, G2, G3, a spline) before any feed F was programmed.";
    FULL_CIRCLE_WITH_RADIUS = "K019", "full-circle-with-radius", Error, "G2 or G3 with CR whose end point is its start point: a radius cannot give a full circle.";
    RADIUS_TOO_SHORT = "K020", "radius-too-short", Error, "G2 or G3 with a radius CR shorter than half the distance from its start to its end.";
    PLUNGE_AT_FULL_FEED = "K022", "plunge-at-full-feed", Warning, "A feed move down in Z alone at the feed of the cut in X or Y that follows it.", opt_in;
    CUT_WITH_SPINDLE_OFF = "K026", "cut-with-spindle-off", Error, "A feed move of X, Y or Z while the spindle stands (M5, M19, or never started in a main program).";
    CUT_WITHOUT_COOLANT = "K027", "cut-without-coolant", Warning, "A feed move of X, Y or Z with the coolant off (M9, or never switched on in a main program).", opt_in;
    SPINDLE_WITHOUT_SPEED = "K029", "spindle-without-speed", Warning, "M3 or M4 before any spindle speed S was programmed.";
    NO_SAFE_BLOCK = "K031", "no-safe-block", Info, "A main program that moves before it writes any of tool radius compensation (G40), a work offset or G90/G91: the modes stand as the machine's reset left them.", opt_in;
    UNREACHABLE_CODE = "K032", "unreachable-code", Info, "Blocks after an end of program or an unconditional jump that no jump, repeated section or structure leads to.", unnecessary;
    END_STOPS_PATH = "K048", "subprogram-end-stops-path", Warning, "A subprogram that ends with M17, M2 or M30 under the continuous-path mode it set: the end stops the path, RET keeps it.";
    CONTOUR_NOT_LINES_AND_ARCS = "K052", "contour-not-lines-and-arcs", Error, "A spline or polynomial inside a CONTPRON contour, which takes only lines and arcs.";
    OFFSETS_NOT_AFTER_TRAORI = "K067", "offsets-not-after-traori", Warning, "A move after TRAORI with no work offset (G54…) or tool offset D programmed since TRAORI.";
    TURN_WHILE_PLUNGING = "K070", "turn-while-plunging", Warning, "A feed move down in Z alone that also turns the tool's orientation (rotary axes, A2 …, A3 …).";
    ORIENTATION_RATE = "K075", "orientation-rate", Warning, "A feed move whose orientation turns by more than 20° per mm of path.";
    SPLINE_FIRST_POINT = "K076", "spline-first-point", Warning, "The first point after BSPLINE 1 µm or more from the current position, which the thesis's programs repeat there.";
    SHORT_MOVE_RUN = "K077", "short-move-run", Hint, "20 or more G1 moves in a row shorter than 1 mm without a compressor or spline: the axes' velocities step at every block.";
    HEAVY_COMPUTATION = "K078", "computation-between-moves", Info, "A loop without motion, or 10 or more computing statements, between two feed moves in continuous-path mode: block preparation may not keep up with the path.";
    PATH_BROKEN = "K081", "path-broken-by-block", Warning, "An M function, MSG, WRITE or STOPRE between two feed blocks in continuous-path mode: the path slows down there.";
}

/// The orientation's turn per mm of path above which rule 75 warns: the
/// digest's example, L27's B2 turning 17° over 0.5 mm (004:4223-4225), is
/// 34°/mm; two of its neighbours turn 28 and 33°/mm.
const ORIENTATION_RATE_DEG_PER_MM: f64 = 20.0;

/// The orientation angles among the walk's followed words (rule 75): the
/// rotary axes and A2, B2, C2; A3 … are a vector's components.
const ANGLES: std::ops::Range<usize> = 3..9;

/// A G1 move shorter than this, in mm, is short (rule 77).
const SHORT_MOVE_MM: f64 = 1.0;

/// This many short G1 moves in a row are a long run (rule 77).
const LONG_RUN: usize = 20;

/// The spline the thesis's programs use, and a word of the compressors'
/// group (rule 77).
const SPLINE: &str = "BSPLINE";
const COMPRESSOR: &str = "COMPCAD";

/// The motion codes CONTPRON takes: lines and arcs of group 1
/// (004:1664-1668).
const CONTOUR_MOTIONS: [&str; 6] = ["G0", "G1", "G2", "G3", "CIP", "CT"];

/// The M functions that stop or end the program on purpose (rule 81).
const STOPS_AND_ENDS: [u64; 5] = [0, 1, 2, 17, 30];

/// This many statements between two feed moves are heavy (rule 78).
const HEAVY_STATEMENTS: usize = 10;

/// The statements rule 81 names that break the path.
const PATH_BREAKERS: [&str; 3] = ["MSG", "WRITE", "STOPRE"];

/// The code of the coolant's group that switches it off.
const COOLANT_OFF: &str = "M9";

/// The groups the safe block writes (rule 31): tool radius compensation,
/// work offset, dimensions.
const SAFE_GROUPS: [&str; 3] = [TOOL_RADIUS, WORK_OFFSETS, DIMENSIONS];

/// The state the rules keep between blocks.
pub(crate) struct Motion {
    /// Rule 48 applies: a subprogram without SAVE.
    ends_path: bool,
    feed_reported: bool,
    /// The M5 or M19 that stopped the spindle, and whether a cut since it
    /// was reported.
    spindle_stop: Option<TextRange>,
    spindle_reported: bool,
    coolant_reported: bool,
    /// Rule 31: which of [`SAFE_GROUPS`] the program wrote before its
    /// first move; `None` once it moved or called a program.
    safe: Option<[bool; 3]>,
    /// The first block of the unreached run rule 32 reports, and its last
    /// block with statements.
    unreached: Option<(usize, usize)>,
    /// The last of the feed moves down in Z since the last cut in X or Y.
    plunge: Option<(TextRange, f64)>,
    contour: Option<TextRange>,
    traori: Option<TextRange>,
    /// The last move was a feed move in continuous-path mode; a block that
    /// broke the path after it.
    on_path: bool,
    break_after: Option<(TextRange, String)>,
    /// Rule 78: the statements computed since the last feed move on the
    /// path, where they start, and a loop among them without motion.
    computed: usize,
    computed_start: Option<TextRange>,
    idle_loop: bool,
    /// The BSPLINE whose first point is still to come.
    spline_start: Option<TextRange>,
    /// The short G1 moves in a row, and where the run starts.
    short_moves: usize,
    short_run_start: Option<TextRange>,
}

/// The whole number of a literal M word.
fn m_number(statement: &Statement) -> Option<u64> {
    match &statement.kind {
        StatementKind::Word(word) if word.address == "M" => match &word.value {
            Some(WordValue::Literal(number)) => number.whole(),
            _ => None,
        },
        _ => None,
    }
}

fn predefined(statement: &Statement) -> Option<&str> {
    match &statement.kind {
        StatementKind::Call(call) => match &call.callee {
            Callee::Predefined(name) => Some(name),
            _ => None,
        },
        StatementKind::Command(command) => Some(&command.name),
        _ => None,
    }
}

impl Motion {
    /// `main`: the file starts at reset.
    pub(crate) fn new(file: &FileModel, main: bool) -> Motion {
        let save = file.model.header().is_some_and(|proc| proc.declaration.attributes.iter().any(|a| a == "SAVE"));
        Motion {
            // Under SAVE the caller's modes come back anyway, and RET is no
            // choice (rule 47).
            ends_path: !main && !save,
            feed_reported: false,
            spindle_stop: None,
            spindle_reported: false,
            coolant_reported: false,
            safe: main.then_some([false; 3]),
            unreached: None,
            plunge: None,
            contour: None,
            traori: None,
            on_path: false,
            break_after: None,
            computed: 0,
            computed_start: None,
            idle_loop: false,
            spline_start: None,
            short_moves: 0,
            short_run_start: None,
        }
    }

    pub(crate) fn step(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let catalogue = Dialect::Sinumerik.catalogue();
        let state = step.state;
        self.unreached(file, step, out);
        // A block no run reaches changes nothing the rules follow.
        if !step.reached {
            return;
        }
        self.safe_block(catalogue, file, step, out);
        self.spindle(file, step, out);
        if step.block.statements.iter().any(|s| word_is(s, "T") || m_number(s) == Some(6)) {
            self.plunge = None;
        }
        self.contour(catalogue, file, step, out);
        if step.state.motion() == Some(SPLINE)
            && let Some(range) = step.find(file, |s| matches!(&s.kind, StatementKind::Command(c) if c.name == SPLINE))
        {
            self.spline_start = Some(range);
        }
        self.traori(catalogue, file, step, out);
        if step.moves {
            let feed_move = state.feed_motion() == Known::Is(true);
            self.missing_feed(file, step, feed_move, out);
            if feed_move {
                self.cut_without_spindle(file, step, out);
                self.cut_without_coolant(file, step, out);
                self.turn_while_plunging(file, step, out);
                self.orientation_rate(file, step, out);
            }
            self.rapid_plunge(file, step, out);
            self.arc_radius(file, step, out);
            self.plunge(file, step, out);
            self.path(step, feed_move, out);
            self.spline_first_point(file, step, out);
            self.short_moves(catalogue, file, step, out);
        } else {
            self.path_breaker(file, step);
            self.computation(file, step);
        }
        if self.ends_path && state.continuous_path() == Known::Is(true) {
            self.end_of_subprogram(file, step, out);
        }
    }

    fn missing_feed(&mut self, file: &FileModel, step: &Step<'_>, feed_move: bool, out: &mut Vec<Diagnostic>) {
        if !feed_move || step.state.feed != Known::Is(None) || self.feed_reported {
            return;
        }
        self.feed_reported = true;
        let motion = step.state.motion().unwrap_or_default();
        let Some(range) = step.find(file, |s| matches!(&s.kind, StatementKind::Word(w) if is_axis(&w.address))) else {
            return;
        };
        let message = format!(
            "{motion} moves at the feed F, and no F was programmed before this block: the control stops with an alarm"
        );
        out.push(Diagnostic::new(&MISSING_FEED, range, message));
    }

    /// Where the spindle was stopped, from the blocks that set its group.
    fn spindle(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let stopped = matches!(step.state.modes.get(SPINDLE), Some("M5" | "M19"));
        if !stopped {
            self.spindle_stop = None;
            self.spindle_reported = false;
        } else if let Some(range) = step.find(file, |s| matches!(m_number(s), Some(5 | 19))) {
            self.spindle_stop = Some(range);
            self.spindle_reported = false;
        }
        // M3 or M4 with no S ever.
        if step.state.speed == Known::Is(None)
            && let Some(range) = step.find(file, |s| matches!(m_number(s), Some(3 | 4)))
        {
            let message = "the spindle starts with no speed S programmed: it turns at S0; write S with M3 or M4";
            out.push(Diagnostic::new(&SPINDLE_WITHOUT_SPEED, range, message));
        }
    }

    fn cut_without_spindle(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let stopped = matches!(step.state.modes.get(SPINDLE), Some("M5" | "M19"));
        let measuring = step.block.statements.iter().any(|s| word_is(s, "MEAS") || word_is(s, "MEAW"));
        if !stopped || measuring || self.spindle_reported {
            return;
        }
        let Some(range) = step.find(file, |s| PATH_AXES.iter().any(|axis| word_is(s, axis))) else { return };
        self.spindle_reported = true;
        let motion = step.state.motion().unwrap_or_default();
        let diagnostic = match self.spindle_stop {
            Some(stop) => Diagnostic::new(
                &CUT_WITH_SPINDLE_OFF,
                range,
                format!("a {motion} feed move with the spindle stopped: start it with M3 or M4 before cutting"),
            )
            .with_related(None, stop, "the spindle stops here"),
            None => Diagnostic::new(
                &CUT_WITH_SPINDLE_OFF,
                range,
                format!("a {motion} feed move before the spindle was started: start it with M3 or M4 before cutting"),
            ),
        };
        out.push(diagnostic);
    }

    /// Rule 27, as rule 26 for the coolant.
    fn cut_without_coolant(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        if step.state.modes.get(COOLANT) != Some(COOLANT_OFF) {
            self.coolant_reported = false;
            return;
        }
        if self.coolant_reported {
            return;
        }
        let Some(range) = step.find(file, |s| PATH_AXES.iter().any(|axis| word_is(s, axis))) else { return };
        self.coolant_reported = true;
        let message = "a feed move with the coolant off: switch it on (M8) before cutting, unless the cut is dry";
        out.push(Diagnostic::new(&CUT_WITHOUT_COOLANT, range, message));
    }

    /// Rule 31: the groups a main program writes before it moves.
    fn safe_block(&mut self, catalogue: &Catalogue, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let Some(written) = &mut self.safe else { return };
        for statement in &step.block.statements {
            let group = match &statement.kind {
                StatementKind::Word(word) if word.address == "G" => {
                    match g_number(word) {
                        // Settable work offsets beyond the catalogue's.
                        Some(505..=599) => Some(WORK_OFFSETS),
                        Some(n) => catalogue.code('G', n).and_then(|code| code.group.as_deref()),
                        None => None,
                    }
                }
                StatementKind::Command(command) => catalogue.word_code(&command.name).and_then(|c| c.group.as_deref()),
                StatementKind::Call(call) if !matches!(call.callee, Callee::Predefined(_) | Callee::Cycle(_)) => {
                    self.safe = None;
                    return;
                }
                _ => None,
            };
            if let Some(slot) = SAFE_GROUPS.iter().position(|g| Some(*g) == group) {
                written[slot] = true;
            }
        }
        if !step.moves {
            return;
        }
        let wrote_any = written.iter().any(|&written| written);
        self.safe = None;
        if wrote_any {
            return;
        }
        let range = step.first_statement(file);
        let message = "the program moves before it writes a safe block: tool radius compensation (G40), a work offset (G54 …, G500) or the dimensions (G90, G91) stand as the machine's reset left them; start with a block such as `G17 G40 G90 G54` (004:493-501)";
        out.push(Diagnostic::new(&NO_SAFE_BLOCK, range, message));
    }

    /// Rule 32: a run of blocks no way reaches.
    fn unreached(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        if step.reached {
            self.report_unreached(file, out);
        } else if !step.block.statements.is_empty() {
            match &mut self.unreached {
                Some((_, last)) => *last = step.index,
                None => self.unreached = Some((step.index, step.index)),
            }
        }
    }

    /// Rule 32 at the end of a run of unreached blocks.
    pub(crate) fn report_unreached(&mut self, file: &FileModel, out: &mut Vec<Diagnostic>) {
        let Some((first, last)) = self.unreached.take() else { return };
        let end =
            file.block(last).statements.last().map_or(file.ranges[last].end(), |s| file.in_file(last, s.range).end());
        let range = TextRange::new(file.ranges[first].start(), end);
        let message = "no jump, repeated section or structure leads here, after an end or an unconditional jump: the control never runs these blocks";
        out.push(Diagnostic::new(&UNREACHABLE_CODE, range, message));
    }

    /// Rule 70: a plunge that turns the orientation (004:2786-2790).
    fn turn_while_plunging(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let (from, to) = (step.from, step.state.position);
        let down = matches!((from[2], to[2]), (Known::Is(from), Known::Is(to)) if to < from - SAME_POINT_MM);
        // A plunge moves Z alone: a surface followed down in 5 axes is none.
        let still = |axis: usize| matches!((from[axis], to[axis]), (Known::Is(a), Known::Is(b)) if (a - b).abs() <= SAME_POINT_MM);
        if !(down && still(0) && still(1)) {
            return;
        }
        let turned: Vec<&str> = (PATH_AXES.len()..FOLLOWED.len())
            .filter(
                |&axis| matches!((from[axis], to[axis]), (Known::Is(a), Known::Is(b)) if (a - b).abs() > f64::EPSILON),
            )
            .map(|axis| FOLLOWED[axis])
            .collect();
        let Some(first) = turned.first() else { return };
        let Some(range) = step.find(file, |s| word_is(s, first)) else { return };
        let message = format!(
            "the tool turns ({}) while it plunges in Z: the thesis's simulation showed a ball-nose cutter entering the material while the table turned to be a problem; plunge first, then turn, or approach along the path (004:2786-2790)",
            turned.join(", ")
        );
        out.push(Diagnostic::new(&TURN_WHILE_PLUNGING, range, message));
    }

    /// Rule 75: the orientation's turn per mm of path.
    fn orientation_rate(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let (from, to) = (step.from, step.state.position);
        let length = (0..PATH_AXES.len()).try_fold(0.0, |sum, axis| match (from[axis], to[axis]) {
            (Known::Is(a), Known::Is(b)) => Some(sum + (b - a) * (b - a)),
            _ => None,
        });
        let Some(length) = length.map(f64::sqrt).filter(|&length| length > SAME_POINT_MM) else { return };
        let turn = ANGLES
            .filter_map(|axis| match (from[axis], to[axis]) {
                (Known::Is(a), Known::Is(b)) => Some((axis, (b - a).abs())),
                _ => None,
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((axis, degrees)) = turn.filter(|(_, degrees)| degrees / length > ORIENTATION_RATE_DEG_PER_MM) else {
            return;
        };
        let Some(range) = step.find(file, |s| word_is(s, FOLLOWED[axis])) else { return };
        let message = format!(
            "{} turns {degrees:.1}° over {length:.2} mm of path ({:.0}°/mm): the rotary axes cannot follow at the feed, so the path slows down, and the surface may show it (004:4223-4225)",
            FOLLOWED[axis],
            degrees / length
        );
        out.push(Diagnostic::new(&ORIENTATION_RATE, range, message));
    }

    /// Rule 16: G0 lowering Z while it moves X or Y.
    fn rapid_plunge(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let state = step.state;
        if state.motion() != Some("G0") {
            return;
        }
        let moves_xy = step.block.statements.iter().any(|s| word_is(s, "X") || word_is(s, "Y"));
        let (Known::Is(from), Known::Is(to)) = (step.from[2], state.position[2]) else { return };
        if !moves_xy || to > from - SAME_POINT_MM {
            return;
        }
        let Some(range) = step.find(file, |s| word_is(s, "Z")) else { return };
        let message = format!(
            "G0 lowers Z from {from} to {to} while it moves X or Y: each axis runs at its own rate, so the tool may reach the work before it is above its point; approach in X and Y first, then in Z"
        );
        out.push(Diagnostic::new(&RAPID_PLUNGE_WITH_XY, range, message));
    }

    /// Rules 19 and 20: an arc by its radius CR.
    fn arc_radius(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let Some(arc) = RadiusArc::of(step.block, &step.from, step.state) else { return };
        let motion = if arc.counter_clockwise { "G3" } else { "G2" };
        let chord = (arc.to[0] - arc.from[0]).hypot(arc.to[1] - arc.from[1]);
        let radius = arc.radius.abs();
        let range = file.in_file(step.index, arc.written.range);
        if chord < SAME_POINT_MM {
            let message = format!(
                "{motion} with CR ends where it starts: a radius gives no full circle; give the centre with I, J, K (or AR=360)"
            );
            out.push(Diagnostic::new(&FULL_CIRCLE_WITH_RADIUS, range, message));
        } else if centre_by_radius(arc.from, arc.to, arc.radius, arc.counter_clockwise, SAME_POINT_MM).is_none() {
            let message = format!(
                "the arc's end is {chord:.3} mm from its start, more than the diameter {:.3} mm of the radius CR={radius}: no such arc joins them",
                2.0 * radius
            );
            out.push(Diagnostic::new(&RADIUS_TOO_SHORT, range, message));
        }
    }

    /// Rule 22: a plunge at the feed of the cut before or after it.
    fn plunge(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let state = step.state;
        let Known::Is(Some(feed)) = state.feed else {
            self.plunge = None;
            return;
        };
        if !matches!(state.motion(), Some("G1" | "G2" | "G3")) {
            return;
        }
        let changed = |axis: usize| match (step.from[axis], state.position[axis]) {
            (Known::Is(from), Known::Is(to)) => Known::Is((to - from).abs() > SAME_POINT_MM),
            _ => Known::Unknown,
        };
        let down =
            matches!((step.from[2], state.position[2]), (Known::Is(from), Known::Is(to)) if to < from - SAME_POINT_MM);
        let full = |cut: f64, plunge: f64| plunge >= cut - SAME_POINT_MM;
        let mut report = |range: TextRange, feed: f64| {
            let message = format!(
                "the tool plunges in Z at F{feed}, the feed of the cut in X or Y after it: plunge at a lower feed (half is the thesis's advice), unless the tool cuts at its centre"
            );
            out.push(Diagnostic::new(&PLUNGE_AT_FULL_FEED, range, message));
        };
        if down && changed(0) == Known::Is(false) && changed(1) == Known::Is(false) {
            self.plunge = step.find(file, |s| word_is(s, "Z")).map(|range| (range, feed));
        } else if changed(0) == Known::Is(true) || changed(1) == Known::Is(true) {
            if let Some((range, plunge)) = self.plunge.take()
                && full(feed, plunge)
            {
                report(range, plunge);
            }
        } else {
            self.plunge = None;
        }
    }

    /// Rule 76: the first point after BSPLINE where the tool stands.
    fn spline_first_point(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let Some(spline) = self.spline_start.take() else { return };
        let differs = (0..3).any(|axis| match (step.from[axis], step.state.position[axis]) {
            (Known::Is(from), Known::Is(to)) => (from - to).abs() > SAME_POINT_MM,
            _ => false,
        });
        if !differs || step.state.motion() != Some(SPLINE) {
            return;
        }
        let Some(range) = step.find(file, |s| PATH_AXES.iter().any(|axis| word_is(s, axis))) else { return };
        let message = "the spline's first point is not where the tool stands: the thesis's programs repeat the current position as the first point, so the spline starts there";
        out.push(Diagnostic::new(&SPLINE_FIRST_POINT, range, message).with_related(None, spline, SPLINE));
    }

    /// Rule 77: runs of short G1 moves without a compressor.
    fn short_moves(&mut self, catalogue: &Catalogue, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        let Some(range) = step.find(file, |s| PATH_AXES.iter().any(|axis| word_is(s, axis))) else { return };
        let state = step.state;
        let compressor_group = catalogue.word_code(COMPRESSOR).and_then(|c| c.group.as_deref());
        // The compressors' group numbers COMPOF first.
        let compressor_off =
            compressor_group.and_then(|group| state.modes.code(group)).is_some_and(|c| c.index == Some(1));
        let length = (0..3).try_fold(0.0, |sum, axis| match (step.from[axis], state.position[axis]) {
            (Known::Is(from), Known::Is(to)) => Some(sum + (to - from) * (to - from)),
            _ => None,
        });
        let short = state.motion() == Some("G1") && compressor_off && length.is_some_and(|l| l.sqrt() < SHORT_MOVE_MM);
        if !short {
            self.short_moves = 0;
            self.short_run_start = None;
            return;
        }
        self.short_moves += 1;
        let start = *self.short_run_start.get_or_insert(range);
        if self.short_moves == LONG_RUN {
            let message = format!(
                "{LONG_RUN} G1 moves in a row shorter than {SHORT_MOVE_MM} mm without a compressor or spline: the axes' velocities step at every block; COMPCAD or a spline smooths the path"
            );
            out.push(Diagnostic::new(&SHORT_MOVE_RUN, start, message));
        }
    }

    /// Rule 81: the move after a block that broke the path.
    fn path(&mut self, step: &Step<'_>, feed_move: bool, out: &mut Vec<Diagnostic>) {
        let on_path = feed_move && step.state.continuous_path() == Known::Is(true);
        if let Some((range, what)) = self.break_after.take()
            && on_path
        {
            let message = format!(
                "{what} between two feed moves in continuous-path mode: the path slows down or stops here; put it before the contour or after it"
            );
            out.push(Diagnostic::new(&PATH_BROKEN, range, message));
        }
        if let Some(start) = self.computed_start.take()
            && on_path
            && (self.idle_loop || self.computed >= HEAVY_STATEMENTS)
        {
            let what = if self.idle_loop {
                "a loop without motion".to_owned()
            } else {
                format!("{} statements without motion", self.computed)
            };
            let message = format!(
                "{what} between two feed moves in continuous-path mode: the control prepares blocks while it moves, and if it cannot keep up the path slows down; compute before the contour, or generate the points beforehand (004:2541-2557)"
            );
            out.push(Diagnostic::new(&HEAVY_COMPUTATION, start, message));
        }
        self.computed = 0;
        self.idle_loop = false;
        self.on_path = on_path;
    }

    /// Rule 78: what a block without motion computes after a feed move on
    /// the path.
    fn computation(&mut self, file: &FileModel, step: &Step<'_>) {
        if !self.on_path {
            return;
        }
        for statement in &step.block.statements {
            let loop_start = matches!(
                statement.kind,
                StatementKind::While(_) | StatementKind::For { .. } | StatementKind::Loop | StatementKind::Repeat
            );
            if matches!(statement.kind, StatementKind::Word(_) | StatementKind::Command(_)) {
                continue;
            }
            if loop_start && let Some(structure) = step.opens {
                let moves = (structure.start..=structure.end).any(|index| {
                    file.block(index)
                        .statements
                        .iter()
                        .any(|s| matches!(&s.kind, StatementKind::Word(w) if is_axis(&w.address)))
                });
                self.idle_loop |= !moves;
            }
            self.computed += 1;
            self.computed_start.get_or_insert(file.in_file(step.index, statement.range));
        }
    }

    /// Rule 81: a block without motion after a feed move on the path.
    fn path_breaker(&mut self, file: &FileModel, step: &Step<'_>) {
        if !self.on_path || self.break_after.is_some() {
            return;
        }
        for statement in &step.block.statements {
            let what = match m_number(statement) {
                Some(number) if !STOPS_AND_ENDS.contains(&number) => Some(format!("M{number}")),
                _ => predefined(statement).filter(|name| PATH_BREAKERS.contains(name)).map(str::to_owned),
            };
            if let Some(what) = what {
                self.break_after = Some((file.in_file(step.index, statement.range), what));
                return;
            }
        }
    }

    /// Rule 52: the motion codes inside CONTPRON … EXECUTE.
    fn contour(&mut self, catalogue: &Catalogue, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        for statement in &step.block.statements {
            match &statement.kind {
                StatementKind::Call(call) if matches!(&call.callee, Callee::Predefined(name) if name == "CONTPRON") => {
                    self.contour = Some(file.in_file(step.index, statement.range));
                }
                StatementKind::Call(call) if matches!(&call.callee, Callee::Predefined(name) if name == "EXECUTE") => {
                    self.contour = None;
                }
                StatementKind::Command(command) => {
                    let Some(start) = self.contour else { continue };
                    let Some(code) = catalogue.word_code(&command.name) else { continue };
                    if code.group.as_deref() == Some(MOTION) && !CONTOUR_MOTIONS.contains(&code.code.as_str()) {
                        let message = format!(
                            "{} inside a contour preparation: CONTPRON takes only lines and arcs of group 1, no splines or polynomials",
                            code.code
                        );
                        let range = file.in_file(step.index, statement.range);
                        out.push(Diagnostic::new(&CONTOUR_NOT_LINES_AND_ARCS, range, message).with_related(
                            None,
                            start,
                            "the contour preparation starts here",
                        ));
                    }
                }
                _ => {}
            }
        }
    }

    /// Rule 67: the first move after TRAORI with no offsets since.
    fn traori(&mut self, catalogue: &Catalogue, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        for statement in &step.block.statements {
            match &statement.kind {
                StatementKind::Command(command) => {
                    if is_transformation(&command.name) {
                        self.traori =
                            command.name.starts_with("TRAORI").then(|| file.in_file(step.index, statement.range));
                    } else if catalogue.word_code(&command.name).and_then(|c| c.group.as_deref()) == Some(WORK_OFFSETS)
                    {
                        self.traori = None;
                    }
                }
                StatementKind::Word(word) if word.address == "D" => self.traori = None,
                StatementKind::Word(word) if word.address == "G" => {
                    let code = g_number(word).and_then(|n| catalogue.code('G', n));
                    if code.and_then(|c| c.group.as_deref()) == Some(WORK_OFFSETS) {
                        self.traori = None;
                    }
                }
                StatementKind::Call(call) if !matches!(call.callee, Callee::Predefined(_)) => self.traori = None,
                _ => {}
            }
        }
        if step.moves
            && let Some(traori) = self.traori.take()
        {
            let range = step.first_statement(file);
            let message = "the first move after TRAORI, with no work offset (G54 …) or tool offset D programmed since: TRAORI may reset them, so program them again after it";
            out.push(Diagnostic::new(&OFFSETS_NOT_AFTER_TRAORI, range, message).with_related(None, traori, "TRAORI"));
        }
    }

    /// Rule 48: M17, M2 or M30 ending a subprogram on the path.
    fn end_of_subprogram(&mut self, file: &FileModel, step: &Step<'_>, out: &mut Vec<Diagnostic>) {
        if !matches!(step.block.program_end(), Some(ProgramEnd::Subprogram | ProgramEnd::Program)) {
            return;
        }
        let end =
            step.block.statements.iter().find_map(|s| m_number(s).filter(|n| matches!(n, 2 | 17 | 30)).map(|n| (s, n)));
        let Some((statement, number)) = end else { return };
        let range = file.in_file(step.index, statement.range);
        let message = format!(
            "M{number} ends the subprogram and the continuous-path mode it set: the caller's next move starts from a stop; RET returns and keeps the path (004:1561-1563)"
        );
        let fix = vec![TextEdit::replace(range, "RET")];
        out.push(Diagnostic::new(&END_STOPS_PATH, range, message).with_fix("Return with RET", fix));
    }
}
