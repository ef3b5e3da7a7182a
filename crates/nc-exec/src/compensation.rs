//! Tool radius compensation G41/G42 (02 §1.5–§1.10, §1.13): the path of the
//! tool centre (the nose-radius centre on lathes) along the equidistants of
//! the programmed contour, with the start, corner and cancel geometry of the
//! equidistant method (machine constant 95 decade 8 = 1).
//!
//! Points are in the compensation plane, its two coordinates in the order in
//! which G02 turns clockwise (the order I and J measure along). In that
//! order G41 keeps the tool on the left of the direction of motion and G42
//! on the right, in every plane: the feed table of 02 §1.13 puts the tool
//! outside a G02 arc under G41.
//!
//! The runner drives a [`Compensator`] with one element of look-ahead, as
//! the control does:
//! 1. The G41/G42 block, a line: [`Compensator::start`]. It yields nothing
//!    yet, since the start move ends on the normal of the next element
//!    (02 §1.7).
//! 2. Each following block that moves in the plane: [`Compensator::push`]
//!    with its contour element. It yields what is now fixed: the start move
//!    on the first push, then the previous element up to its corner and the
//!    corner's inserted arc or joining line. Blocks without motion in the
//!    plane are not pushed (the control bridges up to 200 of them, 02 §1.6);
//!    an element without length is ignored.
//! 3. The G40 block, a line: [`Compensator::cancel`] yields the last element,
//!    ending on the normal at its programmed end, and the move from there to
//!    the G40 block's end (02 §1.9). With machine constant 339 decade 7 = 1
//!    the runner calls it at the first block after G40 that moves in the
//!    plane. A program that ends with compensation in force ends it with
//!    [`Compensator::finish`]: the last element, without a move after it.
//!
//! Each [`ToolElement`] names the block it belongs to, so that the runner
//! charges its time there. The control's [`Settings`] come from its machine
//! constants (CNC8x6: `cnc8x6::dynamics`).
//!
//! On lathes the controlled point is the theoretical tip, a fixed shift of
//! the nose centre by the tool position P (02 §1.11): the runner adds that
//! shift to the path returned here.

use std::{f64::consts::PI, fmt};

use nalgebra::{Point2, Vector2};

/// Lengths (mm) up to this are zero: elements without length, gaps that need
/// no joining line.
const LENGTH_EPS: f64 = 1e-9;

/// Turns (radians) up to this are tangent even when machine constant 234 is
/// zero: "except when the blocks join absolutely tangentially" (000:2867).
const ANGLE_EPS: f64 = 1e-9;

/// A path element in the compensation plane: a programmed block's contour,
/// or a piece of the tool-centre path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Element {
    Line {
        from: Point2<f64>,
        to: Point2<f64>,
    },
    /// An arc about `centre`; `from == to` is a full circle, as in a block.
    Arc {
        from: Point2<f64>,
        to: Point2<f64>,
        centre: Point2<f64>,
        clockwise: bool,
    },
}

impl Element {
    pub fn start(&self) -> Point2<f64> {
        match *self {
            Element::Line { from, .. } | Element::Arc { from, .. } => from,
        }
    }

    pub fn end(&self) -> Point2<f64> {
        match *self {
            Element::Line { to, .. } | Element::Arc { to, .. } => to,
        }
    }

    /// Path length in mm.
    pub fn length(&self) -> f64 {
        match *self {
            Element::Line { from, to } => (to - from).norm(),
            Element::Arc { from, to, centre, clockwise } => {
                let angle = |point: Point2<f64>| (point.y - centre.y).atan2(point.x - centre.x);
                let mut sweep = angle(to) - angle(from);
                // The runner's rule: an arc back to its start is a full circle.
                if !clockwise && sweep <= 0.0 {
                    sweep += std::f64::consts::TAU;
                } else if clockwise && sweep >= 0.0 {
                    sweep -= std::f64::consts::TAU;
                }
                (from - centre).norm() * sweep.abs()
            }
        }
    }

    /// An element whose direction is not defined: a line without length, an
    /// arc with an end on its centre.
    fn is_degenerate(&self) -> bool {
        match *self {
            Element::Line { from, to } => (to - from).norm() <= LENGTH_EPS,
            Element::Arc { from, to, centre, .. } => {
                (from - centre).norm() <= LENGTH_EPS || (to - centre).norm() <= LENGTH_EPS
            }
        }
    }

    /// The unit direction of motion at `point` (a point of the element).
    fn tangent(&self, point: Point2<f64>) -> Vector2<f64> {
        match *self {
            Element::Line { from, to } => (to - from).normalize(),
            Element::Arc { centre, clockwise, .. } => {
                let radial = left((point - centre).normalize());
                if clockwise { -radial } else { radial }
            }
        }
    }
}

/// G41 or G42.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// G41.
    Left,
    /// G42.
    Right,
}

/// What the machine constants select.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Machine constant 339 decade 8 = 1: arcs at outside corners instead of
    /// the intersection of the equidistants (02 §1.8).
    pub insert_arcs: bool,
    /// Machine constant 339 decades 1–6, in radians: an arc is inserted only
    /// where the direction turns by more (02 §1.10).
    pub limit_angle: f64,
    /// Machine constant 234, in radians: a joint that turns by less is
    /// treated as tangent, each element ending on its normal (02 §1.14).
    pub continuity_limit: f64,
    /// Machine constant 168 decade 5 = 0: on compensated arcs the programmed
    /// feed holds at the contact point, not at the tool centre (02 §1.13).
    pub contact_feed: bool,
}

/// A piece of the tool-centre path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolElement {
    /// The block it belongs to, as the runner numbered it.
    pub block: usize,
    pub kind: Piece,
    pub path: Element,
    /// The tool-centre feed over the programmed one: `(R ± Kor)/R` on a
    /// compensated arc of radius R, so that the contact point moves at F
    /// (02 §1.13); 1 elsewhere and when machine constant 168 switches it off.
    pub feed_scale: f64,
}

/// The part a [`ToolElement`] plays.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Piece {
    /// The G41/G42 block's move onto the first equidistant.
    Start,
    /// A programmed element's equidistant, trimmed or extended to its corners.
    Contour,
    /// An arc inserted at an outside corner, or the line joining two
    /// equidistants at a joint treated as tangent; it belongs to the block
    /// after the corner.
    Corner,
    /// The G40 block's move off the last equidistant.
    Cancel,
}

/// Why the control stops under compensation.
#[derive(Debug, Clone, PartialEq)]
pub enum CompensationError {
    /// The equidistants of `block` and the element before it do not meet,
    /// and no arc may be inserted there (02 §1.8).
    NoIntersection { block: usize },
    /// The equidistant of the arc of `block` on its inside has no radius
    /// left: the tool radius is not smaller than the arc's.
    ArcTooSmall { block: usize, arc_radius: f64, tool_radius: f64 },
}

impl CompensationError {
    /// The block the control stops at.
    pub fn block(&self) -> usize {
        match *self {
            CompensationError::NoIntersection { block } | CompensationError::ArcTooSmall { block, .. } => block,
        }
    }
}

impl fmt::Display for CompensationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompensationError::NoIntersection { .. } => f.write_str(
                "equidistant intersection not found (NENALEZEN PRUSEČÍK EKVIDISTANT): the tool-centre paths of this \
                 block and the one before do not meet",
            ),
            CompensationError::ArcTooSmall { arc_radius, tool_radius, .. } => write!(
                f,
                "the tool radius {tool_radius} mm is not smaller than the radius {arc_radius} mm of this arc, on \
                 whose inside the tool runs: the tool-centre path vanishes"
            ),
        }
    }
}

impl std::error::Error for CompensationError {}

/// Radius compensation from its start block to its cancel block.
#[derive(Debug, Clone)]
pub struct Compensator {
    settings: Settings,
    /// The tool centre's signed distance to the left of the contour:
    /// positive for G41 with a positive radius, negative for G42; a negative
    /// radius swaps the sides (02 §1.6).
    offset: f64,
    /// The G41/G42 block and its programmed line.
    start_block: usize,
    start_from: Point2<f64>,
    start_to: Point2<f64>,
    /// The last element pushed, waiting for the next one to fix its end.
    pending: Option<Pending>,
}

#[derive(Debug, Clone, Copy)]
struct Pending {
    block: usize,
    element: Element,
    /// Where its equidistant starts, fixed by the corner before it.
    from: Point2<f64>,
}

/// How the equidistants of two elements join.
struct Joint {
    /// Where the first one ends.
    end: Point2<f64>,
    /// Where the second one starts.
    start: Point2<f64>,
    /// What runs in between: an inserted arc or a joining line.
    link: Option<Element>,
}

impl Compensator {
    /// Starts compensation in `block`, a line from `from` to `to`, with the
    /// radius of the selected correction (datum I of entry D).
    pub fn start(
        settings: Settings,
        side: Side,
        radius: f64,
        block: usize,
        from: Point2<f64>,
        to: Point2<f64>,
    ) -> Compensator {
        let offset = match side {
            Side::Left => radius,
            Side::Right => -radius,
        };
        Compensator { settings, offset, start_block: block, start_from: from, start_to: to, pending: None }
    }

    /// The first block whose tool path is not fixed yet: later pieces belong
    /// to it or to blocks after it.
    pub fn open_block(&self) -> usize {
        self.pending.map_or(self.start_block, |pending| pending.block)
    }

    /// Takes the next contour element, of `block`, and returns the tool path
    /// that is now fixed. On an error nothing changes.
    pub fn push(&mut self, block: usize, element: Element) -> Result<Vec<ToolElement>, CompensationError> {
        if element.is_degenerate() {
            return Ok(Vec::new());
        }
        if let Element::Arc { from, centre, clockwise, .. } = element {
            let arc_radius = (from - centre).norm();
            if self.arc_radius(arc_radius, clockwise) <= LENGTH_EPS {
                return Err(CompensationError::ArcTooSmall { block, arc_radius, tool_radius: self.offset.abs() });
            }
        }
        let mut path = Vec::new();
        let from = match self.pending {
            // The start move ends on the normal at the first element's start (02 §1.7).
            None => {
                let start = self.normal_point(&element, element.start());
                path.push(line(self.start_block, Piece::Start, self.start_from, start));
                start
            }
            Some(pending) => {
                let joint =
                    self.joint(&pending.element, &element).ok_or(CompensationError::NoIntersection { block })?;
                path.push(self.contour(pending, joint.end));
                path.extend(joint.link.map(|link| ToolElement {
                    block,
                    kind: Piece::Corner,
                    path: link,
                    feed_scale: 1.0,
                }));
                joint.start
            }
        };
        self.pending = Some(Pending { block, element, from });
        Ok(path)
    }

    /// Cancels compensation in `block`, a line to `to`: the last element ends
    /// on the normal at its programmed end, and the block runs from there
    /// (02 §1.9). Without an element since the start, both blocks run as
    /// programmed.
    pub fn cancel(self, block: usize, to: Point2<f64>) -> Vec<ToolElement> {
        let last = self.finish();
        vec![last, line(block, Piece::Cancel, last.path.end(), to)]
    }

    /// The tool path still open where compensation ends: the last element
    /// up to the normal at its programmed end, where the tool centre stays
    /// when the program ends with compensation in force, as before a G40
    /// block (02 §1.9); the start block as programmed when no element
    /// followed it.
    pub fn finish(self) -> ToolElement {
        match self.pending {
            Some(pending) => self.contour(pending, self.normal_point(&pending.element, pending.element.end())),
            None => line(self.start_block, Piece::Start, self.start_from, self.start_to),
        }
    }

    /// How the equidistants of `first` and `second` join at the programmed
    /// corner; `None` when they should intersect and do not.
    fn joint(&self, first: &Element, second: &Element) -> Option<Joint> {
        let corner = first.end();
        let (out, into) = (first.tangent(corner), second.tangent(second.start()));
        let (end, start) = (self.normal_point(first, corner), self.normal_point(second, second.start()));
        // Signed turn of direction, positive to the left.
        let turn = out.perp(&into).atan2(out.dot(&into));
        if turn.abs() <= self.settings.continuity_limit.max(ANGLE_EPS) || (end - start).norm() <= LENGTH_EPS {
            // Tangent (or within machine constant 234): each ends on its normal.
            let gap = (end - start).norm() > LENGTH_EPS;
            let link = gap.then_some(Element::Line { from: end, to: start });
            return Some(Joint { end, start: if gap { start } else { end }, link });
        }
        // Outside, the path turns away from the tool; a reversal is outside
        // on either side.
        let outside = turn.abs() > PI - ANGLE_EPS || turn * self.offset < 0.0;
        // The inserted arc's radius is the tool's, about the programmed corner
        // (02 §9 item 15).
        let arc = || Joint {
            end,
            start,
            link: Some(Element::Arc { from: end, to: start, centre: corner, clockwise: self.offset > 0.0 }),
        };
        if outside && self.settings.insert_arcs && turn.abs() > self.settings.limit_angle {
            return Some(arc());
        }
        // Of two intersections the control takes the one nearer the
        // programmed point (000:2893–2898).
        let nearest = intersections(self.equidistant(first), self.equidistant(second))
            .into_iter()
            .min_by(|a, b| (a - corner).norm().total_cmp(&(b - corner).norm()));
        match nearest {
            Some(point) => Some(Joint { end: point, start: point, link: None }),
            // Where the equidistants miss each other an arc is inserted
            // when arcs may be (000:2468–2471).
            None if outside && self.settings.insert_arcs => Some(arc()),
            None => None,
        }
    }

    /// The point of `element`'s equidistant on the normal at `point`.
    fn normal_point(&self, element: &Element, point: Point2<f64>) -> Point2<f64> {
        point + left(element.tangent(point)) * self.offset
    }

    /// The equidistant of an arc of `radius` has this radius.
    fn arc_radius(&self, radius: f64, clockwise: bool) -> f64 {
        // Left of a clockwise arc is its outside.
        if clockwise { radius + self.offset } else { radius - self.offset }
    }

    /// The infinite line or full circle an element's equidistant lies on.
    fn equidistant(&self, element: &Element) -> Curve {
        match *element {
            Element::Line { from, .. } => {
                Curve::Line { point: self.normal_point(element, from), direction: element.tangent(from) }
            }
            Element::Arc { from, centre, clockwise, .. } => {
                Curve::Circle { centre, radius: self.arc_radius((from - centre).norm(), clockwise) }
            }
        }
    }

    /// A pending element's equidistant up to `end`.
    fn contour(&self, pending: Pending, end: Point2<f64>) -> ToolElement {
        let Pending { block, element, from } = pending;
        let (path, feed_scale) = match element {
            Element::Line { .. } => (Element::Line { from, to: end }, 1.0),
            Element::Arc { from: start, centre, clockwise, .. } => {
                let radius = (start - centre).norm();
                let scale = if self.settings.contact_feed { self.arc_radius(radius, clockwise) / radius } else { 1.0 };
                (Element::Arc { from, to: end, centre, clockwise }, scale)
            }
        };
        ToolElement { block, kind: Piece::Contour, path, feed_scale }
    }
}

/// A straight piece of the tool path.
fn line(block: usize, kind: Piece, from: Point2<f64>, to: Point2<f64>) -> ToolElement {
    ToolElement { block, kind, path: Element::Line { from, to }, feed_scale: 1.0 }
}

/// `vector` turned a quarter to the left.
fn left(vector: Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-vector.y, vector.x)
}

/// An equidistant extended beyond its element.
#[derive(Debug, Clone, Copy)]
enum Curve {
    /// Through `point` along the unit vector `direction`.
    Line {
        point: Point2<f64>,
        direction: Vector2<f64>,
    },
    Circle {
        centre: Point2<f64>,
        radius: f64,
    },
}

/// Where two curves meet: none, or one or two points. Parallel lines and
/// concentric circles do not meet; curves that miss each other by up to
/// [`LENGTH_EPS`] touch.
fn intersections(a: Curve, b: Curve) -> Vec<Point2<f64>> {
    match (a, b) {
        (Curve::Line { point: p, direction: d }, Curve::Line { point: q, direction: e }) => {
            let sine = d.perp(&e);
            if sine.abs() <= ANGLE_EPS { Vec::new() } else { vec![p + d * ((q - p).perp(&e) / sine)] }
        }
        (Curve::Line { point, direction }, Curve::Circle { centre, radius })
        | (Curve::Circle { centre, radius }, Curve::Line { point, direction }) => {
            let foot = point + direction * (centre - point).dot(&direction);
            let distance = (centre - foot).norm();
            half_chord(radius, distance)
                .map_or_else(Vec::new, |half| vec![foot - direction * half, foot + direction * half])
        }
        (Curve::Circle { centre: c1, radius: r1 }, Curve::Circle { centre: c2, radius: r2 }) => {
            let between = c2 - c1;
            let distance = between.norm();
            if distance <= LENGTH_EPS {
                return Vec::new();
            }
            let axis = between / distance;
            // The chord's foot lies `along` from c1 towards c2.
            let along = (r1 * r1 - r2 * r2 + distance * distance) / (2.0 * distance);
            let foot = c1 + axis * along;
            half_chord(r1, along.abs())
                .map_or_else(Vec::new, |half| vec![foot - left(axis) * half, foot + left(axis) * half])
        }
    }
}

/// Half the chord a line `distance` from the centre cuts from a circle of
/// `radius`.
fn half_chord(radius: f64, distance: f64) -> Option<f64> {
    if distance <= radius {
        Some((radius * radius - distance * distance).sqrt())
    } else if distance <= radius + LENGTH_EPS {
        Some(0.0)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use expect_test::{Expect, expect};
    use nalgebra::Point2;

    use super::{CompensationError, Compensator, Element, Piece, Settings, Side, ToolElement};
    use crate::machine::MachineConfig;

    const INTERSECTIONS: Settings =
        Settings { insert_arcs: false, limit_angle: 0.0, continuity_limit: 0.0, contact_feed: true };
    const ARCS: Settings = Settings { insert_arcs: true, ..INTERSECTIONS };

    fn p(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    fn line(from: Point2<f64>, to: Point2<f64>) -> Element {
        Element::Line { from, to }
    }

    fn arc(from: Point2<f64>, to: Point2<f64>, centre: Point2<f64>, clockwise: bool) -> Element {
        Element::Arc { from, to, centre, clockwise }
    }

    /// Runs a contour: `blocks[0]` is the start block's line, the last one
    /// the cancel block's; block numbers are the indices.
    fn compensate(
        settings: Settings,
        side: Side,
        radius: f64,
        blocks: &[Element],
    ) -> Result<Vec<ToolElement>, CompensationError> {
        let (first, last) = (blocks[0], blocks[blocks.len() - 1]);
        let mut compensator = Compensator::start(settings, side, radius, 0, first.start(), first.end());
        let mut path = Vec::new();
        for (block, &element) in blocks.iter().enumerate().take(blocks.len() - 1).skip(1) {
            path.extend(compensator.push(block, element)?);
        }
        path.extend(compensator.cancel(blocks.len() - 1, last.end()));
        Ok(path)
    }

    /// One line per piece, coordinates to a micrometre.
    fn show(path: &[ToolElement]) -> String {
        // Adding zero turns -0 into 0.
        let at = |point: Point2<f64>| {
            let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
            format!("({}, {})", round(point.x), round(point.y))
        };
        path.iter()
            .map(|piece| {
                let kind = format!("{:?}", piece.kind);
                let shape = match piece.path {
                    Element::Line { from, to } => format!("line {} → {}", at(from), at(to)),
                    Element::Arc { from, to, centre, clockwise } => {
                        let turn = if clockwise { "cw" } else { "ccw" };
                        format!("arc {turn} {} → {} about {}", at(from), at(to), at(centre))
                    }
                };
                let scale =
                    if piece.feed_scale == 1.0 { String::new() } else { format!(" feed ×{}", piece.feed_scale) };
                format!("N{} {kind:<7} {shape}{scale}\n", piece.block)
            })
            .collect()
    }

    fn check(settings: Settings, side: Side, radius: f64, blocks: &[Element], expected: Expect) {
        match compensate(settings, side, radius, blocks) {
            Ok(path) => expected.assert_eq(&show(&path)),
            Err(error) => expected.assert_eq(&format!("N{}: {error}\n", error.block())),
        }
    }

    /// Up from (0,-10) to (0,0), right along y = 0 to (10,0), down to
    /// (10,-10), off to (20,-10): with G41 the tool is above and then right
    /// of the contour, so the corner at (10,0) is outside.
    fn square_outside() -> [Element; 4] {
        [
            line(p(0.0, -10.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(10.0, 0.0)),
            line(p(10.0, 0.0), p(10.0, -10.0)),
            line(p(10.0, -10.0), p(20.0, -10.0)),
        ]
    }

    #[test]
    fn an_outside_square_corner_goes_to_the_intersection() {
        // G41 r = 2: N1's equidistant is y = 2, N2's is x = 12; they meet at
        // (12,2). The start ends on N1's normal at (0,0): (0,2); the cancel
        // starts on N2's normal at (10,-10): (12,-10).
        check(
            INTERSECTIONS,
            Side::Left,
            2.0,
            &square_outside(),
            expect![[r#"
                N0 Start   line (0, -10) → (0, 2)
                N1 Contour line (0, 2) → (12, 2)
                N2 Contour line (12, 2) → (12, -10)
                N3 Cancel  line (12, -10) → (20, -10)
            "#]],
        );
    }

    #[test]
    fn an_outside_square_corner_gets_an_arc_when_arcs_are_inserted() {
        // N1 ends on its normal at (10,0): (10,2); N2 starts on its normal:
        // (12,0). Between them a quarter circle of radius 2 about the corner,
        // clockwise as the path turns right.
        let blocks = square_outside();
        check(
            ARCS,
            Side::Left,
            2.0,
            &blocks,
            expect![[r#"
                N0 Start   line (0, -10) → (0, 2)
                N1 Contour line (0, 2) → (10, 2)
                N2 Corner  arc cw (10, 2) → (12, 0) about (10, 0)
                N2 Contour line (12, 0) → (12, -10)
                N3 Cancel  line (12, -10) → (20, -10)
            "#]],
        );
        let path = compensate(ARCS, Side::Left, 2.0, &blocks).unwrap();
        assert!((path[2].path.length() - PI).abs() < 1e-12, "a quarter of 2π·2");
    }

    #[test]
    fn an_inside_square_corner_trims_both_elements_in_either_mode() {
        // The same contour under G42: the tool is below N1 (y = -2) and left
        // of N2 (x = 8), inside the corner; both end at (8,-2).
        for settings in [INTERSECTIONS, ARCS] {
            check(
                settings,
                Side::Right,
                2.0,
                &square_outside(),
                expect![[r#"
                    N0 Start   line (0, -10) → (0, -2)
                    N1 Contour line (0, -2) → (8, -2)
                    N2 Contour line (8, -2) → (8, -10)
                    N3 Cancel  line (8, -10) → (20, -10)
                "#]],
            );
        }
    }

    #[test]
    fn a_negative_radius_swaps_the_sides() {
        let blocks = square_outside();
        assert_eq!(compensate(ARCS, Side::Left, -2.0, &blocks), compensate(ARCS, Side::Right, 2.0, &blocks));
        assert_eq!(compensate(ARCS, Side::Right, -2.0, &blocks), compensate(ARCS, Side::Left, 2.0, &blocks));
    }

    #[test]
    fn a_line_runs_into_a_tangent_arc_without_a_corner() {
        // N2 turns counter-clockwise about (10,10), radius 10, starting along
        // +x like N1. G41 r = 2 runs inside it: radius 10 - 2 = 8, from
        // (10,10) + 8·(0,-1) = (10,2) to (10,10) + 8·(1,0) = (18,10), at
        // 8/10 of the feed at the centre. The cancel N3 goes on up along
        // x = 20; the arc ends on its normal at (20,10).
        let blocks = [
            line(p(0.0, -10.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(10.0, 0.0)),
            arc(p(10.0, 0.0), p(20.0, 10.0), p(10.0, 10.0), false),
            line(p(20.0, 10.0), p(20.0, 20.0)),
        ];
        check(
            INTERSECTIONS,
            Side::Left,
            2.0,
            &blocks,
            expect![[r#"
                N0 Start   line (0, -10) → (0, 2)
                N1 Contour line (0, 2) → (10, 2)
                N2 Contour arc ccw (10, 2) → (18, 10) about (10, 10) feed ×0.8
                N3 Cancel  line (18, 10) → (20, 20)
            "#]],
        );
        // Under G42 the tool is outside: radius 12, 12/10 of the feed,
        // unless machine constant 168 switches that off.
        let path = compensate(INTERSECTIONS, Side::Right, 2.0, &blocks).unwrap();
        assert_eq!(path[2].path, arc(p(10.0, -2.0), p(22.0, 10.0), p(10.0, 10.0), false));
        assert_eq!(path[2].feed_scale, 1.2);
        let constant_feed = Settings { contact_feed: false, ..INTERSECTIONS };
        assert_eq!(compensate(constant_feed, Side::Right, 2.0, &blocks).unwrap()[2].feed_scale, 1.0);
    }

    #[test]
    fn two_arcs_meeting_in_a_valley_end_at_their_intersection() {
        // Over the top, clockwise: N1 about (-6,0) from (-16,0) to (0,8), N2
        // about (6,0) from (0,8) to (16,0), both radius 10 (6² + 8² = 10²).
        // At (0,8) the path turns left from (0.8,-0.6) to (0.8,0.6): with G41
        // the tool (outside both arcs, radius 10 + 2 = 12) is inside the
        // corner. The circles of radius 12 about (∓6,0) meet at x = 0,
        // y = ±√(144 - 36) = ±10.392; (0,10.392) is nearer (0,8). Start and
        // cancel: the normals at (-16,0) and (16,0) give (-18,0) and (18,0).
        check(
            ARCS,
            Side::Left,
            2.0,
            &[
                line(p(-16.0, -10.0), p(-16.0, 0.0)),
                arc(p(-16.0, 0.0), p(0.0, 8.0), p(-6.0, 0.0), true),
                arc(p(0.0, 8.0), p(16.0, 0.0), p(6.0, 0.0), true),
                line(p(16.0, 0.0), p(16.0, -10.0)),
            ],
            expect![[r#"
                N0 Start   line (-16, -10) → (-18, 0)
                N1 Contour arc cw (-18, 0) → (0, 10.392) about (-6, 0) feed ×1.2
                N2 Contour arc cw (0, 10.392) → (18, 0) about (6, 0) feed ×1.2
                N3 Cancel  line (18, 0) → (16, -10)
            "#]],
        );
    }

    #[test]
    fn the_manual_lathe_example_matches_its_display_table() {
        // 02 §8 examples 6–8: entry R=0.8 P=3, G41 in N20, G40 in N80, in the
        // lathe plane (X, Z) with X as a radius (the display is diametral).
        // Tip position P=3 puts the theoretical tip at the nose centre
        // + (-0.8, -0.8). E.g. D: N40's equidistant is X = 10.8, N50's line
        // (10,-50)→(20,-75) has the normal (25,10)/√725, so its equidistant
        // is 25(x - 10) + 10(z + 50) = 0.8·√725 = 21.541; at x = 10.8 that
        // gives z = -49.846, the tip -50.646.
        let blocks = [
            line(p(10.0, 50.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(10.0, 0.0)),
            line(p(10.0, 0.0), p(10.0, -50.0)),
            line(p(10.0, -50.0), p(20.0, -75.0)),
            line(p(20.0, -75.0), p(20.0, -100.0)),
            line(p(20.0, -100.0), p(25.0, -100.0)),
            line(p(25.0, -100.0), p(30.0, -100.0)),
        ];
        let path = compensate(INTERSECTIONS, Side::Left, 0.8, &blocks).unwrap();
        let round = |v: f64| (v * 1000.0).round() / 1000.0 + 0.0;
        let display: Vec<(f64, f64)> = path[..6]
            .iter()
            .map(|piece| (round(2.0 * (piece.path.end().x - 0.8)), round(piece.path.end().y - 0.8)))
            .collect();
        assert_eq!(
            display,
            [(-1.6, 0.0), (20.0, 0.0), (20.0, -50.646), (40.0, -75.646), (40.0, -100.0), (48.4, -100.0)]
        );
        // N80 leaves compensation at the programmed point.
        assert_eq!(path[6].path.end(), p(30.0, -100.0));
    }

    #[test]
    fn an_arc_too_small_for_the_tool_on_its_inside_stops_the_control() {
        // Counter-clockwise under G41 the tool is inside: radius 1 - 2 < 0.
        // Radius 2 leaves nothing either; outside (G42) is fine.
        let blocks = |radius: f64| {
            [
                line(p(0.0, -10.0), p(0.0, 0.0)),
                arc(p(0.0, 0.0), p(2.0 * radius, 0.0), p(radius, 0.0), false),
                line(p(2.0 * radius, 0.0), p(2.0 * radius, 10.0)),
            ]
        };
        check(
            ARCS,
            Side::Left,
            2.0,
            &blocks(1.0),
            expect![[r#"
                N1: the tool radius 2 mm is not smaller than the radius 1 mm of this arc, on whose inside the tool runs: the tool-centre path vanishes
            "#]],
        );
        assert_eq!(
            compensate(ARCS, Side::Left, 2.0, &blocks(2.0)),
            Err(CompensationError::ArcTooSmall { block: 1, arc_radius: 2.0, tool_radius: 2.0 })
        );
        assert!(compensate(ARCS, Side::Right, 2.0, &blocks(1.0)).is_ok());
    }

    #[test]
    fn a_reversal_goes_round_the_end_or_stops_without_arcs() {
        // Out along y = 0 and straight back: the equidistants y = 2 and
        // y = -2 are parallel. Arcs: a half circle about (10,0) through
        // (12,0), length 2π. Intersections: none, the control stops.
        let blocks = [
            line(p(0.0, 10.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(10.0, 0.0)),
            line(p(10.0, 0.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(0.0, -10.0)),
        ];
        check(
            ARCS,
            Side::Left,
            2.0,
            &blocks,
            expect![[r#"
                N0 Start   line (0, 10) → (0, 2)
                N1 Contour line (0, 2) → (10, 2)
                N2 Corner  arc cw (10, 2) → (10, -2) about (10, 0)
                N2 Contour line (10, -2) → (0, -2)
                N3 Cancel  line (0, -2) → (0, -10)
            "#]],
        );
        let path = compensate(ARCS, Side::Left, 2.0, &blocks).unwrap();
        assert!((path[2].path.length() - 2.0 * PI).abs() < 1e-12);
        check(
            INTERSECTIONS,
            Side::Left,
            2.0,
            &blocks,
            expect![[r#"
                N2: equidistant intersection not found (NENALEZEN PRUSEČÍK EKVIDISTANT): the tool-centre paths of this block and the one before do not meet
            "#]],
        );
    }

    #[test]
    fn arcs_are_inserted_only_beyond_the_limit_angle() {
        // A right turn by 10° and one by 20° under G41 r = 2, limit 15°. At
        // 10° the equidistants meet 2·tan(5°) = 0.175 beyond the corner
        // (10,0) along y = 2; at 20° an arc runs from (10,2) to
        // (10,0) + 2·(sin 20°, cos 20°) = (10.684, 1.879).
        let settings = Settings { limit_angle: 15f64.to_radians(), ..ARCS };
        let turn = |degrees: f64| {
            let (sin, cos) = degrees.to_radians().sin_cos();
            [
                line(p(0.0, -10.0), p(0.0, 0.0)),
                line(p(0.0, 0.0), p(10.0, 0.0)),
                line(p(10.0, 0.0), p(10.0 + 10.0 * cos, -10.0 * sin)),
                line(p(10.0 + 10.0 * cos, -10.0 * sin), p(30.0, -10.0)),
            ]
        };
        check(
            settings,
            Side::Left,
            2.0,
            &turn(10.0),
            expect![[r#"
                N0 Start   line (0, -10) → (0, 2)
                N1 Contour line (0, 2) → (10.175, 2)
                N2 Contour line (10.175, 2) → (20.195, 0.233)
                N3 Cancel  line (20.195, 0.233) → (30, -10)
            "#]],
        );
        check(
            settings,
            Side::Left,
            2.0,
            &turn(20.0),
            expect![[r#"
                N0 Start   line (0, -10) → (0, 2)
                N1 Contour line (0, 2) → (10, 2)
                N2 Corner  arc cw (10, 2) → (10.684, 1.879) about (10, 0)
                N2 Contour line (10.684, 1.879) → (20.081, -1.541)
                N3 Cancel  line (20.081, -1.541) → (30, -10)
            "#]],
        );
    }

    #[test]
    fn a_joint_within_the_continuity_limit_ends_on_the_normals() {
        // Turning right by 0.001° (under 234's 0.005°) with r = 2: no
        // intersection; the normal points differ by 2·0.001° in radians,
        // 35 nm, and a joining line closes the gap.
        let settings = Settings::of(&MachineConfig::default());
        let (sin, cos) = 0.001f64.to_radians().sin_cos();
        let blocks = [
            line(p(0.0, -10.0), p(0.0, 0.0)),
            line(p(0.0, 0.0), p(10.0, 0.0)),
            line(p(10.0, 0.0), p(10.0 + 10.0 * cos, -10.0 * sin)),
            line(p(10.0 + 10.0 * cos, -10.0 * sin), p(20.0, -10.0)),
        ];
        let path = compensate(settings, Side::Left, 2.0, &blocks).unwrap();
        assert_eq!(path[1].path.end(), p(10.0, 2.0));
        assert_eq!(path[2].kind, Piece::Corner);
        assert!((path[2].path.length() - 2.0 * 0.001f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn a_zero_radius_leaves_the_path_as_programmed() {
        let blocks = square_outside();
        let path = compensate(ARCS, Side::Left, 0.0, &blocks).unwrap();
        let programmed: Vec<Element> = blocks.to_vec();
        assert_eq!(path.iter().map(|piece| piece.path).collect::<Vec<_>>(), programmed);
    }

    #[test]
    fn start_and_cancel_take_the_normals_of_arcs() {
        // N1 is a clockwise half circle about (0,0) from (-5,0) to (5,0),
        // N2 a line down from there. G42 r = 1 puts the tool inside N1
        // (radius 4): it starts at (-4,0); N1 ends heading -y as N2 goes on,
        // a tangent joint at (4,0). N2 ends on its normal at (5,-5): (4,-5).
        check(
            INTERSECTIONS,
            Side::Right,
            1.0,
            &[
                line(p(-10.0, 0.0), p(-5.0, 0.0)),
                arc(p(-5.0, 0.0), p(5.0, 0.0), p(0.0, 0.0), true),
                line(p(5.0, 0.0), p(5.0, -5.0)),
                line(p(5.0, -5.0), p(10.0, -5.0)),
            ],
            expect![[r#"
                N0 Start   line (-10, 0) → (-4, 0)
                N1 Contour arc cw (-4, 0) → (4, 0) about (0, 0) feed ×0.8
                N2 Contour line (4, 0) → (4, -5)
                N3 Cancel  line (4, -5) → (10, -5)
            "#]],
        );
        // A start block followed directly by the cancel runs as programmed.
        let compensator = Compensator::start(ARCS, Side::Left, 2.0, 0, p(0.0, 0.0), p(5.0, 0.0));
        let path = compensator.cancel(1, p(5.0, 5.0));
        assert_eq!(
            path.iter().map(|piece| piece.path).collect::<Vec<_>>(),
            [line(p(0.0, 0.0), p(5.0, 0.0)), line(p(5.0, 0.0), p(5.0, 5.0))]
        );
    }

    #[test]
    fn degenerate_elements_neither_panic_nor_move() {
        let mut compensator = Compensator::start(INTERSECTIONS, Side::Left, 2.0, 0, p(0.0, -5.0), p(0.0, 0.0));
        assert_eq!(compensator.push(1, line(p(0.0, 0.0), p(0.0, 0.0))), Ok(Vec::new()));
        assert_eq!(compensator.push(2, arc(p(0.0, 0.0), p(0.0, 0.0), p(0.0, 0.0), true)), Ok(Vec::new()));
        // A full circle and the same circle back the other way: concentric
        // equidistants (radius 12 and 8) never meet.
        let circle = arc(p(0.0, 0.0), p(0.0, 0.0), p(10.0, 0.0), true);
        assert_eq!(compensator.push(3, circle).map(|path| path.len()), Ok(1));
        let back = arc(p(0.0, 0.0), p(0.0, 0.0), p(10.0, 0.0), false);
        assert_eq!(compensator.push(4, back), Err(CompensationError::NoIntersection { block: 4 }));
        // Nothing changed: the circle still waits, and ends on its normal.
        let path = compensator.cancel(5, p(0.0, -5.0));
        assert_eq!(path[0].path, arc(p(-2.0, 0.0), p(-2.0, 0.0), p(10.0, 0.0), true));
        assert!((path[0].path.length() - 2.0 * PI * 12.0).abs() < 1e-9);
    }

    #[test]
    fn settings_come_from_the_machine_constants() {
        let mut machine = MachineConfig::default();
        assert_eq!(
            Settings::of(&machine),
            Settings {
                insert_arcs: false,
                limit_angle: 0.0,
                continuity_limit: 0.005f64.to_radians(),
                contact_feed: true
            }
        );
        // 339 = 10015.000: arcs beyond 15°; 168 decade 5 = 1.
        machine.constants.extend([(339, 10_015_000), (234, 0), (168, 10_000)]);
        assert_eq!(
            Settings::of(&machine),
            Settings { insert_arcs: true, limit_angle: 15f64.to_radians(), continuity_limit: 0.0, contact_feed: false }
        );
    }
}
