//! Motion geometry (lathe manual §9 rules 14–21): arcs, the feed, corner
//! chamfers and roundings on G01 and lines by angle.

use nc_exec::{arc::circle_through, known::Known};

use crate::{
    Config, Diagnostic,
    diagnostic::declare_rules,
    haas_lathe::{
        checks::{Out, cycles::THREADING},
        walk::{Kind, Setting, Visit, taken},
    },
};

declare_rules! {
    ARC_WITHOUT_CENTRE = "L014", "arc-without-centre", Error, "G02/G03 with neither R nor I/K: the arc has no centre.";
    IMPOSSIBLE_ARC = "L015", "impossible-arc", Error, "An arc whose centre I/K is not as far from its end as from its start, or whose radius R is shorter than half the distance it joins.";
    ARC_OVER_HALF_CIRCLE = "L016", "arc-over-half-circle", Info, "A negative R, which selects the arc of more than 180°.";
    FEED_NEVER_PROGRAMMED = "L017", "feed-never-programmed", Error, "A feed move before any F was programmed.";
    CORNER_NOT_BETWEEN_AXIS_MOVES = "L018", "corner-not-between-axis-moves", Error, "A chamfer or rounding (I/K/R on G01) not between a move along one axis and a G01 move along the other.";
    CORNER_LETTER_MISMATCH = "L019", "corner-letter-mismatch", Error, "A chamfer K after a move along Z, or I after a move along X.";
    CORNER_SIGN_MISMATCH = "L020", "corner-sign-mismatch", Error, "A chamfer or rounding whose sign is not the direction of the move after it.";
    ANGLE_NEEDS_ONE_AXIS = "L021", "angle-needs-one-axis", Error, "A line by angle A (G01) with both X (U) and Z (W), or with neither.";
    ARC_RADIUS_AND_CENTRE = "L103", "arc-radius-and-centre", Warning, "An arc given both by R and by I/K (lathe manual §9 rule 15, its last part).";
}

/// How far apart the two radii of an arc may be because its values are
/// written to 0.001 mm (X as a diameter), besides the machine's
/// tolerance.
const ROUNDING: f64 = 0.002;

pub(crate) fn visit(visit: &Visit<'_>, config: &Config, out: &mut Out) {
    arc(visit, config, out);
    feed(visit, out);
    corner(visit, out);
    angle(visit, out);
}

/// The block's first axis word's range, else its start.
fn axis_range(visit: &Visit<'_>) -> ncc_syntax::TextRange {
    let word = visit.block.words.iter().find(|w| matches!(w.letter, b'X' | b'Z' | b'U' | b'W'));
    word.map_or_else(|| visit.file.in_file(visit.index, Default::default()), |w| visit.range(w))
}

/// Rules 14–16.
fn arc(visit: &Visit<'_>, config: &Config, out: &mut Out) {
    let Kind::Move(Known::Is(code @ (2 | 3))) = visit.kind else { return };
    let block = visit.block;
    let at = if visit.writes(code) { visit.code_range(code) } else { axis_range(visit) };
    let (r, i, k) = (block.word(b'R'), block.word(b'I'), block.word(b'K'));
    if r.is_none() && i.is_none() && k.is_none() {
        let message = format!(
            "G{code:02} without R or I/K: the control has no centre for the arc; give the radius R, or the centre I (a radius) and K from the start point"
        );
        out.push(Diagnostic::new(&ARC_WITHOUT_CENTRE, at, message));
        return;
    }
    if let Some(r) = r
        && let Some(centre) = i.or(k)
    {
        let message =
            "the arc is given both by R and by I/K: give it by one; which the control takes the manual does not say";
        let diagnostic = Diagnostic::new(&ARC_RADIUS_AND_CENTRE, visit.range(r), message).with_related(
            None,
            visit.range(centre),
            char::from(centre.letter).to_string(),
        );
        out.push(diagnostic);
    }
    let before = visit.before;
    let ends = match (before.x, before.z, visit.after.x, visit.after.z) {
        (Known::Is(xs), Known::Is(zs), Known::Is(xe), Known::Is(ze)) => Some(([zs, xs / 2.0], [ze, xe / 2.0])),
        _ => None,
    };
    let tolerance = config.machine.arc_tolerance() + ROUNDING;
    if let Some(word) = r {
        let Known::Is(radius) = before.number(word) else { return };
        let chord = ends.map(|(s, e)| (e[0] - s[0]).hypot(e[1] - s[1]));
        if let Some(chord) = chord
            && chord > 2.0 * radius.abs() + tolerance
        {
            let message = format!(
                "no arc of radius {} mm joins the start and the end point, {} mm apart: the control stops with an alarm",
                radius.abs(),
                round3(chord)
            );
            out.push(Diagnostic::new(&IMPOSSIBLE_ARC, visit.range(word), message));
        } else if radius < 0.0 {
            let sweep = chord.filter(|&chord| chord > 0.0).map(|chord| {
                let short = 2.0 * (chord / (2.0 * radius.abs())).min(1.0).asin().to_degrees();
                format!(": this one sweeps {}°", round3(360.0 - short))
            });
            let message = format!(
                "R{radius} is negative, so the control takes the arc of more than 180° between the points{}",
                sweep.unwrap_or_default()
            );
            out.push(Diagnostic::new(&ARC_OVER_HALF_CIRCLE, visit.range(word), message));
        }
        return;
    }
    let offset = |word: Option<&nc_exec::haas_lathe::lower::Word>| word.map_or(Known::Is(0.0), |w| before.number(w));
    let (Some((start, end)), Known::Is(i_value), Known::Is(k_value)) = (ends, offset(i), offset(k)) else { return };
    // I is a radius along X, K along Z, both from the start point.
    let centre = [start[0] + k_value, start[1] + i_value];
    if let Err(off) = circle_through(start, end, centre, code == 3, tolerance) {
        let message = format!(
            "the end point is not on the arc's circle: the centre I/K is {} mm from the start but {} mm from the end (I is a radius, not a diameter); the control stops with an alarm",
            round3(off.start_radius),
            round3(off.end_radius)
        );
        out.push(Diagnostic::new(&IMPOSSIBLE_ARC, i.or(k).map_or(at, |w| visit.range(w)), message));
    }
}

fn round3(value: f64) -> f64 {
    (value * 1000.0).round() / 1000.0
}

/// Rule 17: a feed move needs an F programmed before.
fn feed(visit: &Visit<'_>, out: &mut Out) {
    if visit.contour.is_some() || visit.after.feed != Setting::Unset {
        return;
    }
    let what = match visit.kind {
        // Without a motion code written, rule 57 says why it feeds.
        Kind::Move(Known::Is(code @ 1..=3)) if visit.after.motion_written == Known::Is(true) => format!("G{code:02}"),
        Kind::Cycle(code) if !THREADING.contains(&code) => format!("the G{code:02} cycle"),
        _ => return,
    };
    let message = format!(
        "{what} moves at feed, but no F has been programmed since the program started: there is no feed to use"
    );
    out.once(visit, Diagnostic::new(&FEED_NEVER_PROGRAMMED, axis_range_or_code(visit), message));
}

/// Where a feed finding stands: the cycle's code, else the first axis word.
fn axis_range_or_code(visit: &Visit<'_>) -> ncc_syntax::TextRange {
    match visit.kind {
        Kind::Cycle(code) if visit.writes(code) => visit.code_range(code),
        _ => axis_range(visit),
    }
}

/// Rules 18–20: a chamfer or rounding, in its block and at the next move.
fn corner(visit: &Visit<'_>, out: &mut Out) {
    if let Some(corner) = visit.after.corner.filter(|corner| corner.block == visit.index) {
        let word = &visit.block.words[corner.word];
        let letter = char::from(word.letter);
        match (corner.along, word.letter) {
            (None, _) => {
                let message = format!(
                    "{letter} makes a corner between two moves along the axes: this block must move along X (U) or along Z (W), not both"
                );
                out.push(Diagnostic::new(&CORNER_NOT_BETWEEN_AXIS_MOVES, visit.range(word), message));
            }
            (Some(b'X'), b'I') | (Some(b'Z'), b'K') => {
                let (axis, right) = if word.letter == b'I' { ("X", 'K') } else { ("Z", 'I') };
                let message = format!("after a move along {axis} the chamfer is written with {right}, not {letter}");
                out.push(Diagnostic::new(&CORNER_LETTER_MISMATCH, visit.range(word), message));
            }
            _ => {}
        }
    }
    let Some(corner) = visit.before.corner else { return };
    let Some(along) = corner.along else { return };
    if visit.kind == Kind::Still {
        return;
    }
    let Some(corner_word) = (corner.block < visit.file.count())
        .then(|| visit.file.block(corner.block))
        .and_then(|b| b.words.get(corner.word))
    else {
        return;
    };
    let corner_range = visit.file.in_file(corner.block, corner_word.range);
    let (other, letters) = if along == b'X' { ('Z', [b'Z', b'W']) } else { ('X', [b'X', b'U']) };
    let written = |axis: [u8; 2]| axis.iter().any(|&l| visit.block.word(l).is_some());
    let same = if along == b'X' { [b'X', b'U'] } else { [b'Z', b'W'] };
    if visit.kind != Kind::Move(Known::Is(1)) || !written(letters) || written(same) {
        let message = format!(
            "the corner {} needs the next move to be a G01 along {other} only; this one is not",
            char::from(corner_word.letter)
        );
        let diagnostic = Diagnostic::new(&CORNER_NOT_BETWEEN_AXIS_MOVES, corner_range, message).with_related(
            None,
            axis_range(visit),
            "the next move",
        );
        out.push(diagnostic);
        return;
    }
    let (from, to) = if along == b'X' { (visit.before.z, visit.after.z) } else { (visit.before.x, visit.after.x) };
    let (Known::Is(from), Known::Is(to), Known::Is(size)) = (from, to, visit.before.number(corner_word)) else {
        return;
    };
    let direction = to - from;
    if direction.abs() > 1e-9 && size != 0.0 && (direction > 0.0) != (size > 0.0) {
        let sign = if direction > 0.0 { "positive" } else { "negative" };
        let message = format!(
            "the next move goes {}{other}, so the corner {}{size} must be {sign} too",
            if direction > 0.0 { '+' } else { '-' },
            char::from(corner_word.letter)
        );
        let diagnostic = Diagnostic::new(&CORNER_SIGN_MISMATCH, corner_range, message).with_related(
            None,
            axis_range(visit),
            "the next move",
        );
        out.push(diagnostic);
    }
}

/// Rule 21: a line by angle gives one coordinate.
fn angle(visit: &Visit<'_>, out: &mut Out) {
    if visit.kind != Kind::Move(Known::Is(1)) {
        return;
    }
    let catalogue = ncc_catalog::Dialect::HaasLathe.catalogue();
    let Some(a) = visit.block.word(b'A').filter(|_| !taken(catalogue, visit.block, b'A')) else { return };
    let x = visit.block.word(b'X').is_some() || visit.block.word(b'U').is_some();
    let z = visit.block.word(b'Z').is_some() || visit.block.word(b'W').is_some();
    if x == z {
        let message = "a line by angle A takes one coordinate, X (U) or Z (W): the angle gives the other";
        out.push(Diagnostic::new(&ANGLE_NEEDS_ONE_AXIS, visit.range(a), message));
    }
}
