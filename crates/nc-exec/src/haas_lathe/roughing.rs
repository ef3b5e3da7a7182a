//! The contour cycles over the blocks P..Q as moves (lathe manual
//! §6.9–§6.14 (001:1553-2226)): the finishing cycle G70, the roughing
//! cycles G71 (Type I and II) and G72, and the contour-parallel roughing
//! G73.
//!
//! The interpreter reads the contour into a [`Profile`]: where the tool
//! starts and the moves of the blocks P to Q, arcs as arcs, without what
//! the cycles do not execute there (F, S, T, corners and angles). The
//! functions here turn it into moves ([`Move`]) or say why the control
//! refuses the cycle.
//!
//! G71 and G72 are one algorithm in a plane (u, v) turned so that the
//! passes run toward −u and step down in v: G71 cuts along Z and steps in
//! X, G72 cuts along X and steps in Z, each axis mirrored as the start
//! point lies to the contour (outside or inside, toward −Z or +Z).
//!
//! Assumptions the manual does not settle:
//! - The allowances U/2, W and the I, K of G71–G73 shift the contour as a
//!   whole, not along its normals.
//! - The roughing levels lie D apart from the shifted start point down to
//!   the shifted contour, strictly above its lowest point: what lies under
//!   the last level (less than D) is left to the pass along the contour.
//! - G71 Type I and G72: each level is entered at the start with the P
//!   block's G00 or G01, cut at feed to where the contour first rises to
//!   it, left by the lift of Setting 73 at 45° and returned from at rapid.
//!   G72 lifts by Setting 73 too (documented for G71 only).
//! - G71 Type II: at each level the tool follows the contour wherever it
//!   lies between this level and the one above (down the P block's move,
//!   into pockets, up the walls) and cuts along the level where the
//!   contour lies lower. Where the contour rises above the level above, the
//!   run ends: the tool lifts by Setting 73 at 45°, goes up to the start
//!   point's height at rapid, across and down to the next run. The contour
//!   must not turn back along Z. Along the contour the roughing passes
//!   feed, its G00 blocks included; only the P block's move keeps its G00.
//! - G71/G72 end with a pass along the contour shifted by the allowances;
//!   with I or K it follows one more along the contour shifted by the
//!   allowances plus I and K, where the levels stop (OQ-11). Each pass is
//!   entered with the P block's move and runs at the cycle's feed, G00
//!   blocks of the contour at rapid.
//! - G73 shares I and K evenly over its D passes, the last one shifted by
//!   the allowances only (OQ-28); each pass runs the contour from the start
//!   point and returns to it.
//! - The passes along the contour run with the tool-nose radius
//!   compensation its blocks program, from the one in force at the cycle
//!   (G71: lathe manual §6.11 (001:1706); G70 finishes the contour as
//!   programmed, §6.9 item 7; G72 and G73 are taken alike); the levels,
//!   the moves between passes and the returns run without.
//! - Every return to the start point goes Z first when the start's X is
//!   smaller than the Q block's, X first otherwise, at rapid: the rule of
//!   G70 and G71 (lathe manual §6.9 item 6 (001:1565-1567)), taken for G72
//!   and G73 and for the returns between passes.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::cycles::{MAX_PASSES, Move, Point, Refused, bounded};
use crate::{
    arc::{CircleArc, circle_through},
    compensation::Side,
};

const EPS: f64 = 1e-9;

/// One move of a contour, from where the one before it ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// A line at rapid (G00) or at feed.
    Line {
        to: Point,
        rapid: bool,
    },
    Arc {
        to: Point,
        centre: Point,
        ccw: bool,
    },
}

impl Piece {
    pub fn to(&self) -> Point {
        match *self {
            Piece::Line { to, .. } | Piece::Arc { to, .. } => to,
        }
    }

    fn shifted(self, by: Point) -> Piece {
        let add = |point: Point| [point[0] + by[0], point[1] + by[1]];
        match self {
            Piece::Line { to, rapid } => Piece::Line { to: add(to), rapid },
            Piece::Arc { to, centre, ccw } => Piece::Arc { to: add(to), centre: add(centre), ccw },
        }
    }

    fn as_move(self) -> Move {
        match self {
            Piece::Line { to, rapid: true } => Move::Rapid(to),
            Piece::Line { to, rapid: false } => Move::Feed(to),
            Piece::Arc { to, centre, ccw } => Move::Arc { to, centre, ccw },
        }
    }
}

/// A cycle's contour in the plane (Z, X radius).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Where the tool is at the cycle's block.
    pub start: Point,
    /// The P block's move from the start, then the moves of the blocks
    /// after it through Q.
    pub pieces: Vec<Piece>,
    /// The tool-nose radius compensation of each piece's block, G41 or
    /// G42 (none: G40); a piece without one runs without.
    pub nose: Vec<Option<Side>>,
}

impl Profile {
    /// The Q block's end point.
    fn end(&self) -> Point {
        self.pieces.last().map_or(self.start, Piece::to)
    }

    /// The pieces shifted by `by` (Z, X): the P block's move leads from the
    /// start to the shifted contour.
    fn shifted(&self, by: Point) -> Vec<Piece> {
        self.pieces.iter().map(|piece| piece.shifted(by)).collect()
    }

    /// One pass along the contour shifted by `by`, with the compensation
    /// its blocks program, and back to the start without.
    fn pass(&self, by: Point, moves: &mut Vec<Move>) {
        let pieces = self.shifted(by);
        let mut nose = None;
        for (index, piece) in pieces.iter().enumerate() {
            let side = self.nose.get(index).copied().flatten();
            if nose != Some(side) {
                moves.push(Move::Nose(side));
                nose = Some(side);
            }
            moves.push(piece.as_move());
        }
        moves.push(Move::Nose(None));
        moves.extend(self.back_from(pieces.last().map_or(self.start, Piece::to)));
    }

    /// Back to the start point: Z first when the start's X is smaller than
    /// the Q block's, else X first (lathe manual §6.9 item 6
    /// (001:1565-1567)).
    fn back_from(&self, from: Point) -> [Move; 2] {
        let (start, q) = (self.start, self.end());
        let corner = if start[1] < q[1] { [start[0], from[1]] } else { [from[0], start[1]] };
        [Move::Rapid(corner), Move::Rapid(start)]
    }
}

/// G70 (lathe manual §6.10 (001:1553-1622)): the contour as programmed,
/// then back to the start point.
pub fn finishing(profile: &Profile) -> Vec<Move> {
    let mut moves = Vec::new();
    profile.pass([0.0; 2], &mut moves);
    moves
}

/// G73 (lathe manual §6.14 (001:2159-2226)): `passes` runs along the
/// contour, the first shifted by the allowances (W, U/2) plus `spread` (K,
/// I), the last by the allowances only.
pub fn pattern_repeat(profile: &Profile, passes: f64, allowance: Point, spread: Point) -> Result<Vec<Move>, Refused> {
    if !(passes >= 1.0 && passes.fract() == 0.0 && passes <= MAX_PASSES as f64) {
        let why = format!(
            "G73 D{passes}: D is the number of passes (lathe manual §6.14 (001:2179)), a whole number from 1 to {MAX_PASSES}"
        );
        return Err(Refused(why));
    }
    let count = passes as usize;
    bounded(count * (profile.pieces.len() + 2), "G73")?;
    let mut moves = Vec::new();
    for pass in 1..=count {
        let share = if count == 1 { 0.0 } else { (count - pass) as f64 / (count - 1) as f64 };
        profile.pass([allowance[0] + spread[0] * share, allowance[1] + spread[1] * share], &mut moves);
    }
    Ok(moves)
}

/// Which roughing cycle runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Roughing {
    /// G71 Type I: passes along Z, no pockets.
    Longitudinal,
    /// G71 Type II: passes along Z, pockets followed.
    Pockets,
    /// G72: facing passes along X.
    Transverse,
}

/// The words of G71 or G72, lengths in the plane (Z, X radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughingWords {
    pub kind: Roughing,
    /// D: the depth of each level.
    pub depth: f64,
    /// (W, U/2): the finishing allowances.
    pub allowance: Point,
    /// (K, I): what the last pass along the contour leaves beyond them.
    pub last_pass: Point,
    /// Setting 73.
    pub lift: f64,
}

/// G71 (lathe manual §6.11–§6.12 (001:1644-2083)) or G72 (§6.13
/// (001:2084-2158)): the levels, the passes along the contour, and back to
/// the start point.
pub fn roughing(profile: &Profile, words: &RoughingWords) -> Result<Vec<Move>, Refused> {
    let RoughingWords { kind, depth, allowance, last_pass, lift } = *words;
    if depth <= 0.0 {
        return Err(Refused(format!("D{depth}: the depth of cut must be above 0 (lathe manual §6.11 (001:1668))")));
    }
    let outer = [allowance[0] + last_pass[0], allowance[1] + last_pass[1]];
    let start = [profile.start[0] + outer[0], profile.start[1] + outer[1]];
    let pieces = profile.shifted(outer);
    let (Some(first), Some(last)) = (pieces.first(), pieces.last()) else {
        return Err(Refused("the blocks P to Q make no move".to_owned()));
    };
    let frame = Frame::new(kind, start, first.to(), last.to());
    let segments = frame.segments(start, &pieces);
    let top = segments[0].from[1];
    let floor = segments[1..].iter().map(Segment::lowest).fold(segments[0].to[1], f64::min);
    let mut levels = Vec::new();
    loop {
        let level = top - depth * (levels.len() + 1) as f64;
        if level <= floor + EPS {
            break;
        }
        if levels.len() == MAX_PASSES {
            return Err(Refused(format!("D{depth} would take more than {MAX_PASSES} roughing passes")));
        }
        levels.push(level);
    }
    bounded(levels.len() * (segments.len() + 4), "the roughing cycle")?;
    let mut path = Path { frame, moves: Vec::new(), at: frame.to(profile.start), line_from: None };
    path.line(segments[0].from, true);
    if kind == Roughing::Pockets {
        path.follow_pockets(&segments, &levels, lift);
    } else {
        path.cut_levels(&segments, &levels, lift);
    }
    let mut moves = path.moves;
    if last_pass != [0.0; 2] {
        profile.pass(outer, &mut moves);
    }
    profile.pass(allowance, &mut moves);
    Ok(moves)
}

/// The turned plane of a roughing cycle: (u, v) from (Z, X) by an optional
/// swap and a sign per axis.
#[derive(Debug, Clone, Copy)]
struct Frame {
    swap: bool,
    su: f64,
    sv: f64,
}

impl Frame {
    /// The frame in which the passes from `start` run toward −u and the
    /// levels step toward the contour's first point `p` in −v; `q` is its
    /// last point.
    fn new(kind: Roughing, start: Point, p: Point, q: Point) -> Frame {
        let sign = |from: f64, to: f64| if from >= to { 1.0 } else { -1.0 };
        match kind {
            Roughing::Transverse => Frame { swap: true, su: sign(start[1], q[1]), sv: sign(start[0], p[0]) },
            _ => Frame { swap: false, su: sign(start[0], q[0]), sv: sign(start[1], p[1]) },
        }
    }

    fn to(&self, [z, x]: Point) -> Point {
        let (u, v) = if self.swap { (x, z) } else { (z, x) };
        [self.su * u, self.sv * v]
    }

    fn from(&self, [u, v]: Point) -> Point {
        let (a, b) = (self.su * u, self.sv * v);
        if self.swap { [b, a] } else { [a, b] }
    }

    /// Whether the frame turns counter-clockwise arcs clockwise.
    fn flips(&self) -> bool {
        (self.su * self.sv < 0.0) != self.swap
    }

    /// The pieces from `start` in the frame. Only the P block's move keeps
    /// its rapid: the roughing passes feed along the contour.
    fn segments(&self, start: Point, pieces: &[Piece]) -> Vec<Segment> {
        let mut from = self.to(start);
        let mut segments = Vec::with_capacity(pieces.len());
        for (index, piece) in pieces.iter().enumerate() {
            let to = self.to(piece.to());
            let shape = match *piece {
                Piece::Line { rapid, .. } => Shape::Line { rapid: rapid && index == 0 },
                // The interpreter checked the ends against the circle.
                Piece::Arc { centre, ccw, .. } => {
                    circle_through(from, to, self.to(centre), ccw != self.flips(), f64::INFINITY)
                        .map_or(Shape::Line { rapid: false }, Shape::Arc)
                }
            };
            segments.push(Segment { from, to, shape });
            from = to;
        }
        segments
    }
}

#[derive(Debug, Clone, Copy)]
enum Shape {
    Line { rapid: bool },
    Arc(CircleArc),
}

/// A piece in the frame, with its start.
#[derive(Debug, Clone, Copy)]
struct Segment {
    from: Point,
    to: Point,
    shape: Shape,
}

impl Segment {
    /// The point a share `t` of the way along.
    fn at(&self, t: f64) -> Point {
        match self.shape {
            _ if t <= 0.0 => self.from,
            _ if t >= 1.0 => self.to,
            Shape::Line { .. } => {
                [self.from[0] + (self.to[0] - self.from[0]) * t, self.from[1] + (self.to[1] - self.from[1]) * t]
            }
            Shape::Arc(arc) => {
                let angle = arc.start_angle + arc.sweep * t;
                [arc.centre[0] + arc.radius * angle.cos(), arc.centre[1] + arc.radius * angle.sin()]
            }
        }
    }

    /// The part from share `t0` to `t1`.
    fn part(&self, t0: f64, t1: f64) -> Segment {
        let shape = match self.shape {
            Shape::Arc(arc) => Shape::Arc(CircleArc {
                start_angle: arc.start_angle + arc.sweep * t0,
                sweep: arc.sweep * (t1 - t0),
                ..arc
            }),
            line => line,
        };
        Segment { from: self.at(t0), to: self.at(t1), shape }
    }

    /// The share of the way along an arc at which it passes `angle`.
    fn share(arc: &CircleArc, angle: f64) -> f64 {
        let turned = if arc.sweep > 0.0 { angle - arc.start_angle } else { arc.start_angle - angle };
        turned.rem_euclid(TAU) / arc.sweep.abs()
    }

    /// The shares strictly inside at which the segment crosses or touches
    /// v = `level`, in order.
    fn crossings(&self, level: f64) -> Vec<f64> {
        let mut shares = match self.shape {
            Shape::Line { .. } => {
                let rise = self.to[1] - self.from[1];
                if rise.abs() < EPS { vec![] } else { vec![(level - self.from[1]) / rise] }
            }
            Shape::Arc(arc) => {
                let sine = (level - arc.centre[1]) / arc.radius;
                if sine.abs() > 1.0 {
                    vec![]
                } else {
                    let angle = sine.asin();
                    vec![Segment::share(&arc, angle), Segment::share(&arc, PI - angle)]
                }
            }
        };
        shares.retain(|&t| t > EPS && t < 1.0 - EPS);
        shares.sort_by(f64::total_cmp);
        shares.dedup_by(|a, b| (*a - *b).abs() < EPS);
        shares
    }

    /// The lowest v along the segment.
    fn lowest(&self) -> f64 {
        let ends = self.from[1].min(self.to[1]);
        match self.shape {
            Shape::Arc(arc) if Segment::share(&arc, -FRAC_PI_2) <= 1.0 => ends.min(arc.centre[1] - arc.radius),
            _ => ends,
        }
    }

    /// Whether the segment lies under v = `level` (it is split at its
    /// crossings, so its middle tells).
    fn below(&self, level: f64) -> bool {
        self.at(0.5)[1] < level - EPS
    }
}

/// The segments split where they cross v = `level`.
fn split(segments: &[Segment], level: f64) -> Vec<Segment> {
    let mut parts = Vec::new();
    for segment in segments {
        let mut shares = vec![0.0];
        shares.extend(segment.crossings(level));
        shares.push(1.0);
        parts.extend(shares.windows(2).map(|t| segment.part(t[0], t[1])));
    }
    parts
}

/// Moves made in the frame, kept in (Z, X).
struct Path {
    frame: Frame,
    moves: Vec<Move>,
    /// Where the tool is, in the frame.
    at: Point,
    /// Where the last move started, when it is a line.
    line_from: Option<Point>,
}

impl Path {
    /// A line to `to`; one that goes on straight from a line of its kind
    /// lengthens it (a level crossing several pieces is one cut).
    fn line(&mut self, to: Point, rapid: bool) {
        let (ahead, before) = (
            [to[0] - self.at[0], to[1] - self.at[1]],
            self.line_from.map(|from| [self.at[0] - from[0], self.at[1] - from[1]]),
        );
        if ahead[0].hypot(ahead[1]) < EPS {
            return;
        }
        let straight_on = before.is_some_and(|before| {
            let cross = before[0] * ahead[1] - before[1] * ahead[0];
            let dot = before[0] * ahead[0] + before[1] * ahead[1];
            cross.abs() <= EPS * before[0].hypot(before[1]) * ahead[0].hypot(ahead[1]) && dot > 0.0
        });
        let point = self.frame.from(to);
        let line = if rapid { Move::Rapid(point) } else { Move::Feed(point) };
        match self.moves.last_mut() {
            Some(last @ (Move::Rapid(_) | Move::Feed(_))) if straight_on && matches!(last, Move::Rapid(_)) == rapid => {
                *last = line
            }
            _ => {
                self.moves.push(line);
                self.line_from = Some(self.at);
            }
        }
        self.at = to;
    }

    fn follow(&mut self, segment: &Segment) {
        match segment.shape {
            Shape::Line { rapid } => self.line(segment.to, rapid),
            Shape::Arc(arc) if arc.radius * arc.sweep.abs() >= EPS => {
                let (to, centre) = (self.frame.from(segment.to), self.frame.from(arc.centre));
                self.moves.push(Move::Arc { to, centre, ccw: (arc.sweep > 0.0) != self.frame.flips() });
                self.at = segment.to;
                self.line_from = None;
            }
            Shape::Arc(_) => {}
        }
    }

    /// G71 Type I and G72: each level from the start to where the contour
    /// (the segments after the P block's) first rises to it.
    fn cut_levels(&mut self, segments: &[Segment], levels: &[f64], lift: f64) {
        let entry = segments[0];
        let (u0, rapid_in) = (entry.from[0], matches!(entry.shape, Shape::Line { rapid: true }));
        let contour = &segments[1..];
        let last = contour.last().unwrap_or(&entry).to[0];
        for &level in levels {
            self.line([u0, level], rapid_in);
            let end = split(contour, level).iter().find(|part| !part.below(level)).map_or(last, |part| part.from[0]);
            if end < u0 - EPS {
                self.line([end, level], false);
                self.line([end + lift, level + lift], true);
                self.line([u0, level + lift], true);
            }
        }
    }

    /// G71 Type II: at each level the runs where the contour (from the
    /// start, the P block's move first) lies under the level above.
    fn follow_pockets(&mut self, segments: &[Segment], levels: &[f64], lift: f64) {
        let top = segments[0].from[1];
        for (index, &level) in levels.iter().enumerate() {
            let above = index.checked_sub(1).map_or(top, |before| levels[before]);
            let parts = split(segments, above);
            for run in parts.split(|part| !part.below(above)).filter(|run| !run.is_empty()) {
                let entry = run[0].from;
                if (entry[0] - self.at[0]).hypot(entry[1] - self.at[1]) >= EPS {
                    let clear = self.at[1].max(top);
                    self.line([entry[0], clear], true);
                    self.line(entry, true);
                }
                for part in split(run, level) {
                    if part.below(level) {
                        self.line([part.to[0], level], false);
                    } else {
                        self.follow(&part);
                    }
                }
                self.line([self.at[0] + lift, self.at[1] + lift], true);
                self.line([self.at[0], self.at[1].max(top)], true);
            }
        }
        let clear = self.at[1].max(top);
        self.line([segments[0].from[0], clear], true);
        self.line(segments[0].from, true);
    }
}
