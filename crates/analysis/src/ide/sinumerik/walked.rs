//! Hover text from the walk over the program's modal state: the arc a CR
//! chooses (digest §6 rule 21) and the programmable frame a frame command
//! leaves in force (rule 74).

use std::ops::ControlFlow;

use nc_exec::{
    arc::{centre_by_radius, circle_through},
    known::Known,
};
use ncc_syntax::TextSize;

use crate::{
    db::{Db, SourceFile},
    sinumerik::{
        model::{file_model, is_main_program},
        walk::{RadiusArc, SAME_POINT_MM, Step, walk},
    },
};

/// What `describe` says of the block at `offset` from the walk's state
/// after it.
fn at_block(
    db: &dyn Db,
    file: SourceFile,
    offset: TextSize,
    describe: impl FnOnce(&Step<'_>) -> Option<String>,
) -> Option<String> {
    let model = file_model(db, file);
    let index = model.ranges.partition_point(|range| range.end() <= offset);
    let mut describe = Some(describe);
    let mut text = None;
    walk(db, model, is_main_program(db, file), |step| {
        if step.index < index {
            return ControlFlow::Continue(());
        }
        text = describe.take().and_then(|describe| describe(&step));
        ControlFlow::Break(())
    });
    text
}

/// The arc the CR of the block at `offset` chooses, where the walk knows
/// both of its ends.
pub(super) fn radius_arc(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<String> {
    at_block(db, file, offset, |step| RadiusArc::of(step.block, &step.from, step.state).map(|arc| describe_arc(&arc)))
}

/// The programmable frame in force after the frame command at `offset`:
/// additive commands compose on top of the frame before them (004:1354-1356).
pub(super) fn composed_frame(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<String> {
    at_block(db, file, offset, |step| {
        Some(match &step.state.composed {
            Known::Is(frame) => format!("**The frame after this block:** {frame}"),
            Known::Unknown => "**The frame after this block** is the run's: a value, the plane or the frame before it is not known without running the program".to_owned(),
        })
    })
}

fn describe_arc(arc: &RadiusArc<'_>) -> String {
    let [a, b] = arc.axes;
    // No `-0.000` for a coordinate a rounding left just below zero.
    let shown = |value: f64| if value.abs() < 0.0005 { 0.0 } else { value };
    let point = |p: [f64; 2]| format!("{a}{:.3} {b}{:.3}", shown(p[0]), shown(p[1]));
    let (from, to) = (point(arc.from), point(arc.to));
    let motion = if arc.counter_clockwise { "G3" } else { "G2" };
    let chosen = if arc.radius < 0.0 { "a negative CR the longer" } else { "a positive CR the shorter" };
    let centre = centre_by_radius(arc.from, arc.to, arc.radius, arc.counter_clockwise, SAME_POINT_MM);
    let swept =
        centre.and_then(|centre| circle_through(arc.from, arc.to, centre, arc.counter_clockwise, SAME_POINT_MM).ok());
    match (centre, swept) {
        (Some(centre), Some(swept)) => format!(
            "**This arc** ({motion}, {chosen} of the two arcs of radius {}): from {from} to {to} about {}, sweeping {:.1}°",
            arc.radius.abs(),
            point(centre),
            swept.sweep.abs().to_degrees()
        ),
        _ => format!("**This arc** ({motion}): no arc of radius {} joins {from} and {to}", arc.radius.abs()),
    }
}
