//! The hover's reading of an arc given by its radius CR (digest §6 rule
//! 21): which of the two arcs of that radius the block cuts, from where the
//! walk over the program's modal state says it starts.

use std::ops::ControlFlow;

use nc_exec::arc::{centre_by_radius, circle_through};
use ncc_syntax::TextSize;

use crate::{
    db::{Db, SourceFile},
    sinumerik::{
        model::{file_model, is_main_program},
        walk::{RadiusArc, SAME_POINT_MM, walk},
    },
};

/// The arc the CR of the block at `offset` chooses, where the walk knows
/// both of its ends (digest §6 rule 21).
pub(super) fn radius_arc(db: &dyn Db, file: SourceFile, offset: TextSize) -> Option<String> {
    let model = file_model(db, file);
    let index = model.ranges.partition_point(|range| range.end() <= offset);
    let mut text = None;
    walk(db, model, is_main_program(db, file), |step| {
        if step.index < index {
            return ControlFlow::Continue(());
        }
        text = RadiusArc::of(step.block, &step.from, step.state).map(|arc| describe_arc(&arc));
        ControlFlow::Break(())
    });
    text
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
