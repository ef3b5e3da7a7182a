//! How the interpreter runs the canned cycles: it reads their words, keeps
//! what stays in force from block to block (the box cycles' target, the
//! drilling cycle's depth, plane and pecks), reads the P..Q contour, and
//! times the moves of [`cycles`] and [`roughing`] as steps of the block.
//!
//! Assumptions the manual does not settle:
//! - G90/G92/G94 keep their target and taper for the blocks that repeat
//!   them with some words (Fanuc keeps them; the manual's example repeats
//!   with X alone, 001:2833-2837); a block that programs G00–G03, G32,
//!   G90, G92 or G94 starts anew.
//! - The contour is read from the tool's position in the motion mode and
//!   the tool-nose radius compensation in force, as the blocks P to Q
//!   program them; the modes they set do not outlast the cycle. A cycle whose contour the program model did not
//!   find (P or Q missing, not found, ambiguous, computed, or Q before P)
//!   stops the run, as a missing call target does.
//! - G84/G184 switch the spindle on (001:1380) and leave it on.
//! - A move of a cycle without a feed or a turning spindle is reported
//!   once for the block, not once per move.

use std::sync::Arc;

use ncc_syntax::TextRange;

use super::{FEED_MODE, Interpreter, MOTION, Moved, STILL};
use crate::{
    arc::circle_through,
    compensation::Side,
    haas_lathe::{
        cycles::{self, Chamfer, Grooving, Hole, Move, MultiThread, Pecks, Point, Refused, Settings, ThreadMethod},
        lower::HaasBlock,
        program::{Contour, RoughingType},
        roughing::{self, Piece, Profile, Roughing, RoughingWords},
    },
    trace::{Axes, Motion, Path, Position, RunRule, Stop, slot},
    transform::over_axes,
};

/// The catalogue's group of M23/M24, the thread chamfer.
const THREAD_CHAMFER: &str = "M10";

/// What the canned cycles keep between blocks.
#[derive(Clone, Default, PartialEq)]
pub(super) struct CycleState {
    /// G90/G92/G94: the last target (Z, X radius) and taper, for the blocks
    /// that repeat the cycle with some of its words (lathe manual §6.18
    /// (001:2833-2837)).
    box_words: Option<(Point, f64)>,
    /// Cleared where G80 or a motion code ends the drilling cycle.
    pub(super) drilling: DrillingWords,
    /// The block's moves before its last: the block turns them into steps
    /// before its own.
    pub(super) pending: Vec<CycleStep>,
    /// The tool-nose radius compensation of a cycle's last move, which the
    /// block's own step makes; `None` when the block ran no cycle.
    pub(super) nose: Option<Option<Side>>,
}

/// A move of a cycle, timed, with its end, stop and compensation.
#[derive(Clone, PartialEq)]
pub(super) struct CycleStep {
    pub(super) moved: Moved,
    pub(super) end: Axes,
    pub(super) stop: Option<Stop>,
    pub(super) nose: Option<Side>,
}

/// The drilling cycle's words as last written, for the blocks that repeat
/// it at another position (lathe manual §6.1 (001:1077-1078)): kept until
/// the cycle ends, as Fanuc and Haas do (the manual does not say).
#[derive(Clone, Default, PartialEq)]
pub(super) struct DrillingWords {
    depth: Option<f64>,
    plane: Option<f64>,
    pecks: Option<Pecks>,
    dwell: Option<f64>,
}

impl Interpreter<'_> {
    /// A G70–G76 block: its cycle's moves, the last one the block's own.
    pub(super) fn canned(&mut self, code: u32, at: usize, block: &HaasBlock, range: TextRange) -> Moved {
        let settings = Settings::of(&self.machine);
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let position = self.position;
        let start = [position[z], position[x]];
        let mut value = |letter| self.value(block, letter, range);
        let (u, w, i, k, d, p, a) =
            (value(b'U'), value(b'W'), value(b'I'), value(b'K'), value(b'D'), value(b'P'), value(b'A'));
        if code >= 74 {
            self.uncompensated(range);
        }
        let moves = match code {
            70..=73 => {
                let Some(contour) = self.units[self.source].contour(at).cloned() else {
                    let message = format!(
                        "G{code}: no contour to run: P or Q is missing, names no block or several, is computed, or Q comes before P"
                    );
                    self.finding(RunRule::CallTargetMissing, range, &message);
                    return STILL;
                };
                let Some(profile) = self.profile(&contour) else { return STILL };
                let allowance = [w.unwrap_or(0.0), u.unwrap_or(0.0) / 2.0];
                let last_pass = [k.unwrap_or(0.0), i.unwrap_or(0.0)];
                match (code, d) {
                    (70, _) => Ok(roughing::finishing(&profile)),
                    (_, None) => Err(Refused(format!("G{code} needs D (lathe manual §6.11–§6.14)"))),
                    (73, Some(passes)) => roughing::pattern_repeat(&profile, passes, allowance, last_pass),
                    (_, Some(depth)) => {
                        let kind = match (code, contour.roughing_type) {
                            (72, _) => Roughing::Transverse,
                            (_, Some(RoughingType::TypeII)) => Roughing::Pockets,
                            _ => Roughing::Longitudinal,
                        };
                        let words = RoughingWords { kind, depth, allowance, last_pass, lift: settings.lift };
                        roughing::roughing(&profile, &words)
                    }
                }
            }
            74 | 75 => {
                let end = self.end_point(block, range, &position).unwrap_or(position);
                let (plunge_axis, peck, step) = if code == 74 { (0, k, i) } else { (1, i, k) };
                cycles::grooving(&Grooving { start, end: [end[z], end[x]], plunge_axis, peck, step }, &settings)
            }
            _ => match (self.end_point(block, range, &position), ThreadMethod::of(p)) {
                (_, Err(refused)) => Err(refused),
                (Some(end), Ok(method)) if block.word(b'X').is_some() || block.word(b'U').is_some() => {
                    let lead = self.feed.unwrap_or(0.0);
                    let thread = MultiThread {
                        start,
                        root: [end[z], end[x]],
                        height: k.unwrap_or(0.0),
                        first: d.unwrap_or(0.0),
                        angle: a.unwrap_or(0.0),
                        taper: i.unwrap_or(0.0),
                        lead,
                        method,
                        chamfer: self.chamfer(lead, &settings),
                    };
                    cycles::multi_thread(&thread, &settings)
                }
                _ => {
                    Err(Refused("G76 needs X or U, the thread's root (lathe manual §6.17 (001:2637-2638))".to_owned()))
                }
            },
        };
        self.emit(range, moves)
    }

    /// A block in G32, G90, G92 or G94 that reaches `end`.
    pub(super) fn modal_cycle(&mut self, code: u32, block: &HaasBlock, range: TextRange, end: &Position) -> Moved {
        self.uncompensated(range);
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let start = [self.position[z], self.position[x]];
        let lead = self.feed.unwrap_or(0.0);
        if code == 32 {
            // Thread cutting G32 (lathe manual §6.8 (001:1486-1552)): a
            // line at one lead F per revolution, no return.
            return self.emit(range, Ok(vec![Move::Thread { to: [end[z], end[x]], lead }]));
        }
        // A block that programs the cycle anew forgets the last one's words.
        if block.codes(b'G').any(|code| matches!(code, 0..=3 | 32 | 90 | 92 | 94)) {
            self.cycles.box_words = None;
        }
        let kept = self.cycles.box_words;
        let written = |absolute, incremental| block.word(absolute).is_some() || block.word(incremental).is_some();
        let target = [
            if written(b'Z', b'W') { end[z] } else { kept.map_or(end[z], |(target, _)| target[0]) },
            if written(b'X', b'U') { end[x] } else { kept.map_or(end[x], |(target, _)| target[1]) },
        ];
        let taper = self.value(block, if code == 94 { b'K' } else { b'I' }, range);
        let taper = taper.or(kept.map(|(_, taper)| taper)).unwrap_or(0.0);
        self.cycles.box_words = Some((target, taper));
        let moves = match code {
            90 => cycles::turning(start, target, taper),
            94 => cycles::facing(start, target, taper),
            _ => cycles::threading_pass(start, target, taper, lead, self.chamfer(lead, &Settings::of(&self.machine))),
        };
        self.emit(range, Ok(moves))
    }

    /// A block that positions under the drilling cycle G81–G89 or G184 in
    /// force: X or U place the hole, Z or W give its depth (lathe manual
    /// §6.1 (001:1075-1082)).
    pub(super) fn drilling(&mut self, code: u32, block: &HaasBlock, range: TextRange, end: &Position) -> Moved {
        if code == 95 {
            // Reported as not run where G95 is programmed.
            return STILL;
        }
        self.uncompensated(range);
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let mut value = |letter| self.value(block, letter, range);
        let (plane, q, i, j, k, repeats) =
            (value(b'R'), value(b'Q'), value(b'I'), value(b'J'), value(b'K'), value(b'L'));
        let dwell = block.word(b'P').and_then(|word| self.seconds(word, range));
        let state = &mut self.cycles.drilling;
        if block.word(b'Z').is_some() || block.word(b'W').is_some() {
            state.depth = Some(end[z]);
        }
        state.plane = plane.or(state.plane);
        state.dwell = dwell.or(state.dwell);
        let degressive = [i, j, k].iter().any(Option::is_some);
        if q.is_some() && degressive {
            let why = "G83: Q and I, J, K must not be programmed in the same block (lathe manual §6.4 (001:1326))";
            return self.emit(range, Err(Refused(why.to_owned())));
        }
        if let Some(q) = q {
            state.pecks = Some(Pecks::Constant(q));
        } else if degressive {
            let (first, less, least) = (i.unwrap_or(0.0), j.unwrap_or(0.0), k.unwrap_or(0.0));
            state.pecks = Some(Pecks::Degressive { first, less, least });
        }
        let Some(depth) = state.depth else {
            let why = format!("G{code} has no depth Z or W to drill to");
            return self.emit(range, Err(Refused(why)));
        };
        let hole_start = [self.position[z], end[x]];
        let plane = state.plane.unwrap_or(hole_start[0]);
        let (pecks, dwell) = (state.pecks.unwrap_or(Pecks::Whole), state.dwell.unwrap_or(0.0));
        let lead = match code {
            84 | 184 => self.tap_lead(code, range, end[x]),
            _ => 0.0,
        };
        let hole = Hole { code, x: end[x], plane, depth, pecks, dwell, lead };
        let settings = Settings::of(&self.machine);
        let moves = match repeats.unwrap_or(1.0) {
            times if times >= 0.0 && times.fract() == 0.0 && times <= cycles::MAX_PASSES as f64 => {
                cycles::drilling(&hole, &settings).and_then(|one| {
                    cycles::bounded(one.len() * times as usize, &format!("G{code} L{times}"))?;
                    let mut moves = vec![Move::Rapid(hole_start)];
                    for _ in 0..times as usize {
                        moves.extend_from_slice(&one);
                    }
                    Ok(moves)
                })
            }
            times => Err(Refused(format!("L{times}: the number of holes is a whole number from 0"))),
        };
        self.emit(range, moves)
    }

    /// The lead of a tap: F under G99, F over the rpm under G98 (lathe
    /// manual §6.5 (001:1381)). The cycle switches the spindle on itself,
    /// G84 clockwise, G184 counter-clockwise (001:1380).
    fn tap_lead(&mut self, code: u32, range: TextRange, radius: f64) -> f64 {
        self.modes.set('M', if code == 84 { 3 } else { 4 });
        let feed = self.feed.unwrap_or(0.0);
        if self.modes.get(FEED_MODE) == Some(98) {
            self.spindle_rpm(range, radius).map_or(0.0, |rpm| feed / rpm)
        } else {
            feed
        }
    }

    /// The thread's end chamfer when M23 is in force.
    fn chamfer(&self, lead: f64, settings: &Settings) -> Option<Chamfer> {
        (self.modes.get(THREAD_CHAMFER) == Some(23))
            .then_some(Chamfer { length: settings.chamfer_leads * lead, angle: settings.chamfer_angle })
    }

    /// A word's value in the block.
    fn value(&mut self, block: &HaasBlock, letter: u8, range: TextRange) -> Option<f64> {
        block.word(letter).and_then(|word| self.number(word, range))
    }

    /// The moves of the blocks P to Q from the tool's position, in the
    /// motion modes and tool-nose radius compensation they program from the
    /// ones in force; the P block's move first (zero long when it has no X
    /// or Z). `None` after reporting an arc off its circle.
    fn profile(&mut self, contour: &Contour) -> Option<Profile> {
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let unit = Arc::clone(&self.units[self.source]);
        let mut position = self.position;
        let start = [position[z], position[x]];
        let (mut mode, mut side) = (self.modes.get(MOTION), self.nose_side());
        let (mut pieces, mut nose) = (Vec::new(), Vec::new());
        for index in contour.blocks.clone() {
            let (block, range) = (&unit.block(index), unit.ranges[index]);
            for code in block.codes(b'G') {
                match code {
                    0..=3 => mode = Some(code),
                    40 => side = None,
                    41 => side = Some(Side::Left),
                    42 => side = Some(Side::Right),
                    _ => {}
                }
            }
            // Roughing ignores corners and angles (lathe manual §6.9 item 10).
            if matches!(contour.code, 70 | 73) {
                self.unrun_corners(block, range, mode);
            }
            let Some(end) = self.end_point(block, range, &position) else {
                if pieces.is_empty() {
                    pieces.push(Piece::Line { to: start, rapid: mode == Some(0) });
                    nose.push(side);
                }
                continue;
            };
            let (from, to) = ([position[z], position[x]], [end[z], end[x]]);
            pieces.push(match mode {
                Some(code @ (2 | 3)) => {
                    let arc = self.arc(block, range, from, to, code == 3)?;
                    Piece::Arc { to, centre: arc.centre, ccw: code == 3 }
                }
                _ => Piece::Line { to, rapid: mode == Some(0) },
            });
            nose.push(side);
            position = end;
        }
        Some(Profile { start, pieces, nose })
    }

    /// Times a cycle's moves from the tool's position, moving it: the last
    /// move is returned for the block's step, the others wait in
    /// [`CycleState::pending`]. A refused cycle is reported and moves
    /// nothing.
    pub(super) fn emit(&mut self, range: TextRange, moves: Result<Vec<Move>, Refused>) -> Moved {
        let moves = match moves {
            Ok(moves) => moves,
            Err(Refused(why)) => {
                self.finding(RunRule::CycleFailed, range, &why);
                return STILL;
            }
        };
        let (z, x) = (slot(b'Z'), slot(b'X'));
        let findings = self.findings.len();
        let (mut last, mut nose): (Option<CycleStep>, _) = (None, None);
        for step in moves {
            let from = [self.position[z], self.position[x]];
            let (moved, to, stop) = match step {
                Move::Nose(side) => {
                    nose = side;
                    continue;
                }
                Move::Rapid(to) | Move::Feed(to) | Move::Thread { to, .. } | Move::Arc { to, .. }
                    if (to[0] - from[0]).hypot(to[1] - from[1]) < 1e-9 =>
                {
                    continue;
                }
                Move::Rapid(to) => {
                    let length = (to[0] - from[0]).hypot(to[1] - from[1]);
                    let duration = self.rapid_seconds(from, to);
                    (Moved { motion: Motion::Rapid, path: Path::Straight, length, duration, feed: None }, to, None)
                }
                Move::Feed(to) => {
                    let length = (to[0] - from[0]).hypot(to[1] - from[1]);
                    (self.feed_move(range, from, to, Path::Straight, length), to, None)
                }
                Move::Arc { to, centre, ccw } => {
                    let length = circle_through(from, to, centre, ccw, f64::INFINITY).map_or(0.0, |arc| arc.length());
                    let path = Path::Arc { plane: (b'Z', b'X'), centre, clockwise: !ccw };
                    (self.feed_move(range, from, to, path, length), to, None)
                }
                Move::Thread { to, lead } => (self.thread_move(range, from, to, lead), to, None),
                Move::Dwell(duration) => (Moved { motion: Motion::Dwell, duration, ..STILL }, from, None),
                Move::Stop => (STILL, from, Some(Stop::Program)),
            };
            (self.position[z], self.position[x]) = (to[0], to[1]);
            let end = over_axes(&self.position, self.machine.step_axes());
            if let Some(before) = last.replace(CycleStep { moved, end, stop, nose }) {
                self.cycles.pending.push(before);
            }
        }
        // One finding of a kind for the block, not one per move.
        let mut seen = Vec::new();
        for finding in self.findings.split_off(findings) {
            if !seen.contains(&finding.rule) {
                seen.push(finding.rule);
                self.findings.push(finding);
            }
        }
        match last {
            Some(CycleStep { moved, stop: None, nose, .. }) => {
                self.cycles.nose = Some(nose);
                moved
            }
            Some(stopping) => {
                self.cycles.nose = Some(None);
                self.cycles.pending.push(stopping);
                STILL
            }
            None => {
                self.cycles.nose = Some(None);
                STILL
            }
        }
    }

    /// Reports tool-nose radius compensation in force at a cycle that has
    /// no pass along a contour, whose moves run without it.
    fn uncompensated(&mut self, range: TextRange) {
        if self.nose_side().is_some() {
            let what = "tool-nose radius compensation in G32, G74–G76, G90/G92/G94 and the drilling cycles (their moves run without it)";
            self.not_run(what, range);
        }
    }

    /// A move synchronised with the spindle at `lead` mm per revolution.
    fn thread_move(&mut self, range: TextRange, from: Point, to: Point, lead: f64) -> Moved {
        let length = (to[0] - from[0]).hypot(to[1] - from[1]);
        let untimed = Moved { motion: Motion::Feed, path: Path::Straight, length, duration: 0.0, feed: None };
        if lead <= 0.0 {
            let message = "no lead F programmed before this thread or tap";
            self.finding(RunRule::MotionWithoutFeed, range, message);
            return untimed;
        }
        let Some(speed) = self.spindle_rpm(range, (from[1] + to[1]) / 2.0) else { return untimed };
        let rate = lead * speed;
        Moved {
            motion: Motion::Feed,
            path: Path::Thread { lead, speed },
            length,
            duration: length / rate * 60.0,
            feed: Some(rate),
        }
    }
}
