//! The Haas lathe's one-block canned cycles as moves: the box cycles G90,
//! G92 and G94 (lathe manual §6.18–§6.20 (001:2792-2987)), the threading
//! cycle G76 (§6.17 (001:2635-2785)), the grooving cycles G74 and G75
//! (§6.15–§6.16 (001:2227-2634)) and the drilling and tapping cycles
//! G81–G89, G184 (§6.1–§6.6 (001:1065-1425)). The contour cycles G70–G73
//! are in [`super::roughing`].
//!
//! Everything here is pure: a cycle's words in, its moves out ([`Move`],
//! ends in the plane (Z, X) with X a radius), or why the control refuses
//! it ([`Refused`]). The interpreter times the moves as steps.
//!
//! Assumptions the manual does not settle:
//! - The Settings it names without a value ([`Settings`]): the lift of
//!   Setting 73 is 0.5 mm, a usual roughing retract; the last thread pass
//!   of Setting 86 is 0, so that the D·√n passes alone reach K; the
//!   chamfer of Setting 95 is one lead, Haas's usual value; the least
//!   deepening of Setting 99 is 0.025 mm, small enough to change the
//!   passes only where √n would make them thinner. A machine sets them.
//! - G90/G92 taper I is a radius, the cut's start-side radius minus its
//!   end radius, and G94 taper K the Z at the start X minus the target Z
//!   (Fanuc's R; the manual's sign figure only says that I follows U,
//!   lathe manual §6.18 (001:2852-2860), OQ-14).
//! - The box cycles rapid in, cut, and G90/G94 feed out while G92 rapids
//!   out, then rapid back to the start (Fanuc's boxes; the manual gives
//!   only the figures).
//! - The thread chamfer of M23 ends at the programmed Z: the thread proper
//!   stops Setting 95 × F short of it ("the thread length Z is shortened",
//!   §6.17 (001:2673)) and pulls out over that length at the Setting 96
//!   angle from Z. Without M23 (M24, or neither since power-on) there is
//!   no chamfer.
//! - G76 D·√n is the depth reached after pass n (Fanuc's reading, OQ-27);
//!   every pass after the first goes at least Setting 99 deeper; the passes
//!   stop at K less Setting 86, and a last pass of Setting 86 reaches K.
//!   P3/P4 go D deeper each pass. Without P the method is P1. The flank
//!   methods P1/P3 start each pass shifted along the cut by depth ×
//!   tan(A/2), so that the tool's trailing edge follows the flank; the
//!   thread end stays at Z.
//! - G76 K may be written with a sign; its size is the height.
//! - G74/G75: the plunge goes in pecks (K for G74, I for G75) with a rapid
//!   retract of Setting 22 after each, a rapid back to the plunge's start,
//!   then the next groove one step over (I for G74, K for G75, the last
//!   step shorter), and finally back to the start point. A step word left
//!   out spans the whole distance (one plunge, or grooves at the start and
//!   the end only); an end left out cuts one groove at the start. The I of
//!   G75 is a radius, as the I of G74 is. D ("Zdvih", OQ-12, OQ-13) is
//!   left out.
//! - Drilling runs along Z at the hole's X, reached at rapid first. R is
//!   an absolute Z (OQ-7); without R the plane is the start Z. Every
//!   return goes to the R plane, as the manual's steps all do (001:1173,
//!   1235, 1319, 1373, 1402, 1410; G98/G99 are feed modes on this control,
//!   so there is no return to the start plane), moved by Setting 52 away
//!   from the hole (it "can influence the return plane R", 001:1191). W of
//!   the depth counts from the start Z. L repeats the hole where it is;
//!   L0 only positions.
//! - G83 re-enters each peck at rapid down to Setting 22 above the depth
//!   reached (the "A" of the figure); degressive pecks shrink by J down to
//!   K, and need K when J is given (else they would vanish).
//! - The dwell P runs where the manual lists it: G82, G83, G88, G89.
//! - G84/G184 tap and retract at one lead per revolution. G86's spindle
//!   stop and restart and G84's reversal take no time (the run models no
//!   spindle ramps). G87/G88 stop at the bottom for the operator's manual
//!   retract, counted as a rapid back to the R plane after the stop.

use crate::{compensation::Side, machine::MachineConfig};

/// A point of the plane (Z, X), X a radius.
pub type Point = [f64; 2];

/// One move or action of a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Move {
    /// G00 to a point.
    Rapid(Point),
    /// G01 at the feed in force.
    Feed(Point),
    /// An arc at the feed in force, counter-clockwise or not in (Z, X).
    Arc { to: Point, centre: Point, ccw: bool },
    /// A move synchronised with the spindle at `lead` mm per revolution: a
    /// thread or a tap.
    Thread { to: Point, lead: f64 },
    /// Seconds.
    Dwell(f64),
    /// The program stops for the operator (the manual retract of G87/G88).
    Stop,
    /// Tool-nose radius compensation for the moves after it: G41 (left),
    /// G42 (right) or none (G40). A pass along a contour of G70–G73 runs
    /// with the compensation its blocks program (lathe manual §6.9 item 7
    /// (001:1706)); every other move of a cycle runs without.
    Nose(Option<Side>),
}

/// Why the control refuses a cycle: said at its block.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refused(pub String);

/// The most passes, pecks or repetitions of one cycle: a bound for a depth
/// or step too small for its distance (a D of 0.0001 or a stray Q).
pub const MAX_PASSES: usize = 10_000;

/// The most moves one cycle block may make, where passes multiply (pecks
/// of many grooves, repeated holes, passes over a long contour).
pub const MAX_MOVES: usize = 100_000;

/// Refuses a cycle whose `moves` would pass [`MAX_MOVES`].
pub fn bounded(moves: usize, what: &str) -> Result<(), Refused> {
    if moves > MAX_MOVES {
        return Err(Refused(format!("{what} would make more than {MAX_MOVES} moves")));
    }
    Ok(())
}

const EPS: f64 = 1e-9;

/// The Settings the cycles read (lathe manual §6.22). A machine sets them
/// as its constants, in thousandths of the unit (`R22 = "0.3"`); the ones
/// it leaves out take the manual's value or, where it gives none, an
/// assumed one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Setting 22, mm: the retract after a peck or step, and how far above
    /// the material G83 re-enters (0.25, 001:1190).
    pub peck_retract: f64,
    /// Setting 52, mm: how far the return plane lies beyond R (0, 001:1191).
    pub return_plane: f64,
    /// Setting 73, mm: the lift between roughing passes (001:1717-1718).
    /// Not given: 0.5 assumed.
    pub lift: f64,
    /// Setting 86, mm: the depth of the last thread pass (001:2686). Not
    /// given: 0 assumed, the last D·√n pass reaching K.
    pub thread_finish: f64,
    /// Setting 95, leads: the thread chamfer's length (001:2661-2662). Not
    /// given: 1 assumed (Haas's usual value).
    pub chamfer_leads: f64,
    /// Setting 96, degrees: the thread chamfer's angle (45, 001:2649).
    pub chamfer_angle: f64,
    /// Setting 99, mm: the least deepening of a thread pass after the first
    /// (001:2684-2685). Not given: 0.025 assumed.
    pub min_cut: f64,
}

impl Settings {
    pub fn of(machine: &MachineConfig) -> Settings {
        let setting = |number, otherwise| machine.constants.get(&number).map_or(otherwise, |&raw| raw as f64 / 1000.0);
        Settings {
            peck_retract: setting(22, 0.25),
            return_plane: setting(52, 0.0),
            lift: setting(73, 0.5),
            thread_finish: setting(86, 0.0),
            chamfer_leads: setting(95, 1.0),
            chamfer_angle: setting(96, 45.0),
            min_cut: setting(99, 0.025),
        }
    }
}

/// How many steps of `step` cover `distance`, the last one shorter;
/// refused beyond [`MAX_PASSES`].
fn steps(distance: f64, step: f64, what: &str) -> Result<usize, Refused> {
    let count = (distance / step - EPS).ceil().max(1.0);
    if count > MAX_PASSES as f64 {
        return Err(Refused(format!("{what} would take more than {MAX_PASSES} passes")));
    }
    Ok(count as usize)
}

/// The point a share `t` of the way from `a` to `b`.
fn between(a: Point, b: Point, t: f64) -> Point {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// G90 (lathe manual §6.18 (001:2792-2860)): from `start` in X to the
/// target's X (plus the taper), along Z to `target` at feed, out in X at
/// feed, back in Z.
pub fn turning(start: Point, target: Point, taper: f64) -> Vec<Move> {
    vec![
        Move::Rapid([start[0], target[1] + taper]),
        Move::Feed(target),
        Move::Feed([target[0], start[1]]),
        Move::Rapid(start),
    ]
}

/// G94 (lathe manual §6.20 (001:2918-2987)): in Z to the target's Z (plus
/// the taper), across in X to `target` at feed, back in Z at feed, out in X.
pub fn facing(start: Point, target: Point, taper: f64) -> Vec<Move> {
    vec![
        Move::Rapid([target[0] + taper, start[1]]),
        Move::Feed(target),
        Move::Feed([start[0], target[1]]),
        Move::Rapid(start),
    ]
}

/// A thread's chamfer at its end (M23): its length along Z and its angle
/// from Z in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chamfer {
    pub length: f64,
    pub angle: f64,
}

/// One threading pass (G92, lathe manual §6.19 (001:2861-2917), and each
/// pass of G76): in X to the target's X plus the taper, the thread to
/// `target` (its chamfer pulling out toward the start X), out in X, back
/// in Z, all but the thread at rapid.
pub fn threading_pass(start: Point, target: Point, taper: f64, lead: f64, chamfer: Option<Chamfer>) -> Vec<Move> {
    let entry = [start[0], target[1] + taper];
    let mut moves = vec![Move::Rapid(entry)];
    let length = (target[0] - entry[0]).abs();
    match chamfer.filter(|chamfer| chamfer.length > EPS && length > EPS) {
        Some(Chamfer { length: chamfer, angle }) => {
            let chamfer = chamfer.min(length);
            let short = between(entry, target, 1.0 - chamfer / length);
            let outward = (start[1] - target[1]).signum();
            let lift = chamfer * angle.to_radians().tan();
            moves.push(Move::Thread { to: short, lead });
            moves.push(Move::Thread { to: [target[0], short[1] + outward * lift], lead });
        }
        None => moves.push(Move::Thread { to: target, lead }),
    }
    moves.push(Move::Rapid([target[0], start[1]]));
    moves.push(Move::Rapid(start));
    moves
}

/// How G76 cuts, its P (lathe manual §6.17 (001:2680-2785)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThreadMethod {
    /// P1/P3: along the flank; P2/P4: radially.
    pub flank: bool,
    /// P3/P4: D deeper each pass; P1/P2: D·√n.
    pub constant_depth: bool,
}

impl ThreadMethod {
    /// The method of `P`: 1 to 4, P1 when left out.
    pub fn of(p: Option<f64>) -> Result<ThreadMethod, Refused> {
        match p.unwrap_or(1.0) {
            1.0 => Ok(ThreadMethod { flank: true, constant_depth: false }),
            2.0 => Ok(ThreadMethod { flank: false, constant_depth: false }),
            3.0 => Ok(ThreadMethod { flank: true, constant_depth: true }),
            4.0 => Ok(ThreadMethod { flank: false, constant_depth: true }),
            other => Err(Refused(format!("G76 P{other}: the cutting method is P1 to P4 (lathe manual §6.17)"))),
        }
    }
}

/// The depth each G76 pass reaches below the crest, the last one the
/// thread height `height`: the first `first` deep, then D·√n (or n·D for
/// the constant-depth methods), each at least `min_cut` deeper than the
/// one before, up to `height` less `finish`, then a pass of `finish`.
pub fn thread_depths(
    height: f64,
    first: f64,
    method: ThreadMethod,
    min_cut: f64,
    finish: f64,
) -> Result<Vec<f64>, Refused> {
    if first <= 0.0 {
        let why = "G76: D, the depth of the first pass, must be given and above 0 (lathe manual §6.17 (001:2641))";
        return Err(Refused(why.to_owned()));
    }
    let height = height.abs();
    if height <= 0.0 {
        return Err(Refused("G76 needs K, the thread height (lathe manual §6.17 (001:2640))".to_owned()));
    }
    let roughed = (height - finish.max(0.0)).max(0.0);
    let mut depths: Vec<f64> = Vec::new();
    for n in 1..=MAX_PASSES {
        let n = n as f64;
        let formula = if method.constant_depth { n * first } else { first * n.sqrt() };
        let depth = depths.last().map_or(formula, |&last| formula.max(last + min_cut));
        if depth >= roughed - EPS {
            if depths.last().is_none_or(|&last| roughed > last + EPS) {
                depths.push(roughed);
            }
            if height > roughed + EPS {
                depths.push(height);
            }
            return Ok(depths);
        }
        depths.push(depth);
    }
    Err(Refused(format!("G76 would cut more than {MAX_PASSES} passes of D{first} to K{height}")))
}

/// G76's words, positions as in the plane (Z, X radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultiThread {
    pub start: Point,
    /// The thread root's radius at the end, and the end Z.
    pub root: Point,
    pub height: f64,
    pub first: f64,
    /// The tool's angle A in degrees.
    pub angle: f64,
    pub taper: f64,
    pub lead: f64,
    pub method: ThreadMethod,
    pub chamfer: Option<Chamfer>,
}

/// G76 (lathe manual §6.17 (001:2635-2785)): a threading pass per depth of
/// [`thread_depths`], from the crest (root plus the height, on the start's
/// side) toward the root, then back to the start.
pub fn multi_thread(thread: &MultiThread, settings: &Settings) -> Result<Vec<Move>, Refused> {
    let MultiThread { start, root, height, first, angle, taper, lead, method, chamfer } = *thread;
    let depths = thread_depths(height, first, method, settings.min_cut, settings.thread_finish)?;
    let outward = if start[1] >= root[1] { 1.0 } else { -1.0 };
    let crest = root[1] + outward * height.abs();
    let along = (root[0] - start[0]).signum();
    let flank = if method.flank { (angle.to_radians() / 2.0).tan() } else { 0.0 };
    let mut moves = Vec::new();
    for depth in depths {
        let pass_start = [start[0] + along * depth * flank, start[1]];
        moves.push(Move::Rapid(pass_start));
        moves.extend(threading_pass(pass_start, [root[0], crest - outward * depth], taper, lead, chamfer));
    }
    moves.push(Move::Rapid(start));
    Ok(moves)
}

/// A grooving cycle's words (G74, G75), positions in the plane (Z, X
/// radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grooving {
    pub start: Point,
    pub end: Point,
    /// The axis the tool plunges along: 0 for Z (G74), 1 for X (G75).
    pub plunge_axis: usize,
    /// The peck (K of G74, I of G75).
    pub peck: Option<f64>,
    /// The step between grooves (I of G74, K of G75).
    pub step: Option<f64>,
}

/// G74/G75 (lathe manual §6.15–§6.16 (001:2227-2634)): grooves from the
/// start toward the end, each plunged in pecks with a retract of Setting
/// 22 after each, then back to the start point.
pub fn grooving(groove: &Grooving, settings: &Settings) -> Result<Vec<Move>, Refused> {
    let Grooving { start, end, plunge_axis: p, peck, step } = *groove;
    let s = 1 - p;
    let positive = |value: Option<f64>, what: &str| match value {
        Some(value) if value <= 0.0 => Err(Refused(format!("{what} must be above 0, not {value}"))),
        value => Ok(value),
    };
    let (peck, step) = (positive(peck, "the peck")?, positive(step, "the step between grooves")?);
    let across = end[s] - start[s];
    let grooves =
        if across.abs() > EPS { steps(across.abs(), step.unwrap_or(across.abs()), "the grooves")? } else { 0 };
    let depth = end[p] - start[p];
    let pecks = if depth.abs() > EPS { steps(depth.abs(), peck.unwrap_or(depth.abs()), "the pecks")? } else { 0 };
    bounded((grooves + 1) * (2 * pecks + 2), "the grooving cycle")?;
    let at = |plunge: f64, side: f64| {
        let mut point = [0.0; 2];
        (point[p], point[s]) = (plunge, side);
        point
    };
    let mut moves = Vec::new();
    for groove in 0..=grooves {
        let side =
            if groove == grooves { end[s] } else { start[s] + across.signum() * step.unwrap_or(0.0) * groove as f64 };
        moves.push(Move::Rapid(at(start[p], side)));
        for k in 1..=pecks {
            let reached = if k == pecks { end[p] } else { start[p] + depth.signum() * peck.unwrap_or(0.0) * k as f64 };
            moves.push(Move::Feed(at(reached, side)));
            if k < pecks {
                moves.push(Move::Rapid(at(reached - depth.signum() * settings.peck_retract, side)));
            }
        }
        moves.push(Move::Rapid(at(start[p], side)));
    }
    moves.push(Move::Rapid(start));
    Ok(moves)
}

/// How a drilling cycle goes in: G83's pecks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pecks {
    /// In one go.
    Whole,
    /// Q each (lathe manual §6.3 (001:1192-1251)).
    Constant(f64),
    /// I first, each following one J less but at least K (§6.4
    /// (001:1263-1333)).
    Degressive { first: f64, less: f64, least: f64 },
}

/// A drilling or tapping cycle's words for one hole, along Z at `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hole {
    /// 81–89 or 184.
    pub code: u32,
    pub x: f64,
    /// The reference plane R, a Z.
    pub plane: f64,
    /// The final depth, a Z.
    pub depth: f64,
    pub pecks: Pecks,
    /// Seconds at the bottom.
    pub dwell: f64,
    /// The tap's lead, mm per revolution (G84, G184).
    pub lead: f64,
}

/// One hole of a drilling or tapping cycle (lathe manual §6.1–§6.6
/// (001:1065-1425)): at rapid to R, in to the depth as the cycle does,
/// back to the return plane.
pub fn drilling(hole: &Hole, settings: &Settings) -> Result<Vec<Move>, Refused> {
    let Hole { code, x, plane, depth, pecks, dwell, lead } = *hole;
    let at = |z: f64| [z, x];
    let into = (depth - plane).signum();
    let back = at(plane - into * settings.return_plane);
    let dwell = (matches!(code, 82 | 83 | 88 | 89) && dwell > 0.0).then_some(Move::Dwell(dwell));
    let mut moves = vec![Move::Rapid(at(plane))];
    match code {
        83 => {
            let reached = peck_depths((depth - plane).abs(), pecks)?;
            for (index, &peck) in reached.iter().enumerate() {
                if let Some(&before) = index.checked_sub(1).and_then(|before| reached.get(before)) {
                    let above = (before - settings.peck_retract).max(0.0);
                    moves.extend([Move::Rapid(back), Move::Rapid(at(plane + into * above))]);
                }
                moves.push(Move::Feed(at(plane + into * peck)));
            }
            moves.extend(dwell);
            moves.push(Move::Rapid(back));
        }
        84 | 184 => moves.extend([Move::Thread { to: at(depth), lead }, Move::Thread { to: back, lead }]),
        85 => moves.extend([Move::Feed(at(depth)), Move::Feed(back)]),
        87 | 88 => {
            moves.push(Move::Feed(at(depth)));
            moves.extend(dwell);
            moves.extend([Move::Stop, Move::Rapid(back)]);
        }
        _ => {
            moves.push(Move::Feed(at(depth)));
            moves.extend(dwell);
            moves.push(Move::Rapid(back));
        }
    }
    Ok(moves)
}

/// The depths below R each peck reaches, the last `total`.
fn peck_depths(total: f64, pecks: Pecks) -> Result<Vec<f64>, Refused> {
    let (mut size, less, least) = match pecks {
        Pecks::Whole => (total, 0.0, 0.0),
        Pecks::Constant(size) => (size, 0.0, 0.0),
        Pecks::Degressive { first, less, least } => (first, less, least),
    };
    let mut reached = vec![];
    let mut depth = 0.0;
    while depth < total - EPS {
        if size <= 0.0 {
            let why = "G83: the pecks must be above 0 (lathe manual §6.3, §6.4 (001:1243, 1325)); with J a least peck K is needed";
            return Err(Refused(why.to_owned()));
        }
        if reached.len() == MAX_PASSES {
            return Err(Refused(format!("G83 would peck more than {MAX_PASSES} times")));
        }
        depth = (depth + size).min(total);
        reached.push(depth);
        if less > 0.0 {
            size = (size - less).max(least);
        }
    }
    Ok(reached)
}
