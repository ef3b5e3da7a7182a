//! The CNC8x6 and CNC8x9 velocity policy: the parameters of the velocity
//! model and the envelope planner, read from the machine constants (R39,
//! R52, R97, R236, R237, R338, R382–R432) with what the manual assumes
//! where the configuration gives none; and the settings of radius
//! compensation (R168, R234, R339). The planners themselves (`velocity`,
//! `envelope`) and the compensator read no machine constant.

use std::fmt;

use crate::{
    compensation::Settings,
    envelope::{DynamicSet, Envelope, MAX_DEPTH, P_PER_JERK, ProfileKind},
    machine::MachineConfig,
    ramp::Ramp,
    trace::PathMode,
    velocity::{Dynamics, Joining, MachineTimes, Reason, Terms},
};

/// The interpolator tick of the CNC8x6 (000:2749).
const TICK: f64 = 0.01;
/// The largest distance of a chord from its circle the control allows (000:2747).
const CHORD_ERROR: f64 = 0.001;

/// Moves shorter in time (ms) than these at their programmed speed cannot
/// be joined smoothly (G23) or tightly (G24), on a CNC8x6 and on a CNC8x9
/// (000:7006, 000:6965).
pub const MIN_CONTINUITY_MS: (f64, f64) = (60.0, 4.0);
pub const MIN_TIGHT_JOINING_MS: (f64, f64) = (30.0, 2.0);

/// Machine constant R39 in degrees (thousandths, the decimal point valid).
pub fn tolerance_angle(machine: &MachineConfig) -> f64 {
    machine.constant(39) as f64 / 1000.0
}

/// The CNC8x6 or CNC8x9 value of a limit: envelope velocity (R338 decade
/// 2) exists only on CNC8x9; otherwise the control is the CNC8x6.
pub fn for_control(machine: &MachineConfig, (cnc8x6, cnc8x9): (f64, f64)) -> f64 {
    if matches!(machine.known_decade(338, 2), Some(1 | 2)) { cnc8x9 } else { cnc8x6 }
}

/// What the model assumes for machine constants the manual gives no value
/// for, until the machine's configuration sets them: automatic continuity,
/// R52 and R237 of 1000 mm/s², and the manual's example of 400 mm/s² for
/// R236. The checker assumes nothing: its continuity rules wait for R97.
const ASSUMED_JOINING: Joining = Joining::Automatic;
const ASSUMED_ACCELERATIONS: [(u32, i64); 3] = [(52, 1000), (236, 400), (237, 1000)];

/// The velocity model's parameters for `machine`: the one-block look-ahead
/// of the CNC8x6, or the CNC8x9 envelope when R338 switches it on.
pub fn dynamics(machine: &MachineConfig) -> Dynamics {
    Dynamics { envelope: envelope(machine), ..one_block_look_ahead(machine) }
}

/// The CNC8x6 model's constants, which the envelope builds on.
fn one_block_look_ahead(machine: &MachineConfig) -> Dynamics {
    let acceleration = |number| {
        let assumed = ASSUMED_ACCELERATIONS.iter().find(|&&(n, _)| n == number).map(|&(_, value)| value);
        machine.known_constant(number).or(assumed).unwrap_or(0).unsigned_abs() as f64
    };
    let feed_acceleration = acceleration(52);
    let continuity_acceleration = match acceleration(236) {
        0.0 => feed_acceleration,
        value => value,
    };
    Dynamics {
        // A digit the manual does not define joins as manual continuity does.
        joining: machine
            .known_decade(97, 1)
            .map_or(ASSUMED_JOINING, |decade| joining(decade).unwrap_or(Joining::Programmed)),
        tolerance_angle: tolerance_angle(machine),
        tolerance_cosine: tolerance_angle(machine).to_radians().cos(),
        feed_acceleration,
        continuity_acceleration,
        rapid_acceleration: acceleration(237),
        times: MachineTimes::of(machine),
        min_continuity: for_control(machine, MIN_CONTINUITY_MS) / 1000.0,
        min_tight_joining: for_control(machine, MIN_TIGHT_JOINING_MS) / 1000.0,
        tick: TICK,
        chord_error: CHORD_ERROR,
        // The manual gives no spindle run-up: the spindle is taken to follow.
        spindle_acceleration: f64::INFINITY,
        // Linear ramps; the envelope's sets bring their own jerk.
        jerk: None,
        envelope: None,
        terms: &TERMS,
    }
}

/// How a block of the code in force in group G2 is joined to the one
/// before: G23 on a continuous path, G24 after an exact stop, G98 (and G09
/// for a helix) after a stop and a pause.
pub fn path_mode(joining_code: Option<u32>) -> PathMode {
    match joining_code {
        Some(23) => PathMode::Continuous,
        Some(24) => PathMode::ExactStop,
        _ => PathMode::Stop,
    }
}

/// How R97 decade 1 joins G23 blocks: 0 not at all, 1 manually (every
/// G23 block), 2 by automatic recognition (000:6988-7025).
pub fn joining(decade: u8) -> Option<Joining> {
    match decade {
        0 => Some(Joining::Off),
        1 => Some(Joining::Programmed),
        2 => Some(Joining::Automatic),
        _ => None,
    }
}

/// What the planner assumes for the constants the manual gives no value
/// for, until the configuration sets them: its examples, R384 and R409 =
/// 8 µm, R385 and R410 = 10000 mm/s², R383 = 0.005 mm, P (R407) = 50000
/// and A (R408) = 600 mm/s² (04 §1.9 A6.2, §2.2).
const ASSUMED_ENVELOPE: [(u32, i64); 7] =
    [(384, 8), (385, 10_000), (383, 5), (407, 50_000), (408, 600), (409, 8), (410, 10_000)];

/// The machine's envelope velocity, or `None` when machine constant R338
/// decade 2 does not switch it on (then the CNC8x6 model applies).
pub fn envelope(machine: &MachineConfig) -> Option<Envelope> {
    let profile = match machine.known_decade(338, 2) {
        Some(1) => ProfileKind::Linear,
        Some(2) => ProfileKind::Parabolic,
        _ => return None,
    };
    let dynamics = one_block_look_ahead(machine);
    let raw = |number: u32| {
        let assumed = ASSUMED_ENVELOPE.iter().find(|&&(n, _)| n == number).map(|&(_, value)| value);
        machine.known_constant(number).or(assumed).unwrap_or(0)
    };
    let digits = |value: i64, decades: u32| (value.unsigned_abs() % 10u64.pow(decades)) as f64;
    // P in decades 1–7; decade 8 scales it down for very flat parabolas.
    let jerk_of = |value: i64| {
        let scale = match value.unsigned_abs() / 10_000_000 % 10 {
            2 => 100.0,
            3 => 1000.0,
            _ => 1.0,
        };
        match profile {
            ProfileKind::Linear => f64::INFINITY,
            ProfileKind::Parabolic => digits(value, 7) / scale / P_PER_JERK,
        }
    };
    let jerk = jerk_of(raw(407));
    // A minus sign blocks the length limits; their point is mm.
    let length = |number| (raw(number).max(0) as f64) / 1000.0;
    let mut set = DynamicSet {
        ramp: Ramp { acceleration: dynamics.continuity_acceleration, jerk },
        accuracy: digits(raw(384), 4) / 1000.0,
        overload: digits(raw(385), 7),
        centrifugal: 0.0,
    };
    let mut rapid = Ramp { acceleration: dynamics.rapid_acceleration, jerk };
    let mut sets = [set; 4];
    // The sets govern the parabolic profile when R406 decade 1 is 1;
    // then R236, R384 and R385 have no effect (04 §2.2).
    if profile == ProfileKind::Parabolic && machine.decade(406, 1) == 1 {
        // A set's value, when the set is on, holds it directly (not a
        // program parameter's number) and is not zero.
        let value = |set: u32, offset: u32| {
            let base = 406 + 6 * set;
            let on = set == 0 || machine.decade(base, 1) == 1;
            let direct = machine.decade(base, offset + 1) == 0;
            let value = if set == 0 { raw(base + offset) } else { machine.constant(base + offset) };
            (on && direct && value != 0).then_some(value)
        };
        let centrifugal = |value: i64| {
            let new_method = value.unsigned_abs() / 10_000_000 % 10 == 1;
            if new_method { digits(value, 7) / 10.0 } else { 0.0 }
        };
        // Set 1's unknown values (in program parameters) keep what the
        // control uses without the sets.
        set = DynamicSet {
            ramp: Ramp {
                acceleration: value(0, 2).map_or(set.ramp.acceleration, |a| digits(a, 8)),
                jerk: value(0, 1).map_or(set.ramp.jerk, jerk_of),
            },
            accuracy: value(0, 3).map_or(set.accuracy, |v| digits(v, 4) / 1000.0),
            overload: value(0, 4).map_or(set.overload, |v| digits(v, 7)),
            centrifugal: value(0, 5).map_or(0.0, centrifugal),
        };
        for (n, slot) in sets.iter_mut().enumerate() {
            let n = n as u32;
            *slot = DynamicSet {
                ramp: Ramp {
                    acceleration: value(n, 2).map_or(set.ramp.acceleration, |a| digits(a, 8)),
                    jerk: value(n, 1).map_or(set.ramp.jerk, jerk_of),
                },
                accuracy: value(n, 3).map_or(set.accuracy, |v| digits(v, 4) / 1000.0),
                overload: value(n, 4).map_or(set.overload, |v| digits(v, 7)),
                centrifugal: value(n, 5).map_or(set.centrifugal, centrifugal),
            };
        }
        // R430–R432 for G00, falling back to set 1 (04 §2.2).
        let own =
            |number: u32| (machine.decade(430, 1) == 1).then(|| machine.constant(number)).filter(|&value| value != 0);
        rapid = Ramp {
            acceleration: own(432).map_or(set.ramp.acceleration, |a| digits(a, 8)),
            jerk: own(431).map_or(set.ramp.jerk, jerk_of),
        };
    }
    let hold = match raw(395) {
        // 0 is the basic setting of 0.5 s (04 §1.9.3).
        0 => 0.5,
        ms => ms.unsigned_abs() as f64 / 1000.0,
    };
    Some(Envelope {
        profile,
        depth: (machine.look_ahead_blocks as usize).clamp(1, MAX_DEPTH),
        tick: f64::from(machine.envelope_tick_us.max(1)) / 1e6,
        min_duration: MIN_CONTINUITY_MS.1 / 1000.0,
        short_block: length(382),
        merge_below: length(383),
        hold_time: hold,
        sets,
        rapid,
        basic: Ramp { acceleration: dynamics.feed_acceleration, jerk: set.ramp.jerk },
    })
}

impl Settings {
    /// The settings of `machine`. The manual gives no unit for the limit
    /// angle of 339; it is read in thousandths of a degree like 234 (and 39,
    /// whose angle it should not exceed), so `10015.000` inserts arcs beyond
    /// 15°.
    pub fn of(machine: &MachineConfig) -> Settings {
        let degrees = |thousandths: i64| (thousandths as f64 / 1000.0).to_radians();
        Settings {
            insert_arcs: machine.decade(339, 8) == 1,
            limit_angle: degrees(machine.constant(339).abs() % 1_000_000),
            continuity_limit: degrees(machine.constant(234).abs()),
            contact_feed: machine.decade(168, 5) == 0,
        }
    }
}

/// The reasons of breaks as the CNC8x6 manual names them.
static TERMS: Terms = Terms { code, describe };

/// A short name for scripts.
fn code(reason: &Reason) -> &'static str {
    match reason {
        Reason::Unjoined => "g98",
        Reason::ExactStop => "g24",
        other => other.neutral_code(),
    }
}

/// The reason in the control's terms.
fn describe(reason: &Reason, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match reason {
        Reason::Unjoined => f.write_str("G98 joins no blocks: a stop and a pause before the next"),
        Reason::ExactStop => f.write_str("G24 tight joining: a stop and the in-position wait"),
        Reason::JoiningOff => f.write_str("G23 without continuity: machine constant R97 decade 1 is 0"),
        Reason::Corner { angle, limit } => write!(f, "a corner of {angle:.1}°, not below R39 ({limit:.3}°)"),
        Reason::Rapid => f.write_str("a rapid move (G00) is never joined smoothly"),
        Reason::Thread => f.write_str("a thread (G33) runs from a stop, without ramps"),
        Reason::NonMotion => f.write_str("a block without motion between moves"),
        Reason::ShortBlock { duration, limit } => write!(
            f,
            "a block of {:.0} ms at its feed, shorter than the {:.0} ms continuity needs",
            duration * 1000.0,
            limit * 1000.0
        ),
        Reason::BeyondThreeAxes => f.write_str("continuity is recognised on the first three axes only"),
        Reason::LookAhead => f.write_str("one block of look-ahead: the next block must be able to stop within itself"),
        Reason::ArcLimit { radius } => write!(
            f,
            "an arc of radius {radius:.3} mm: at most {:.0} µm chord error per interpolator tick",
            CHORD_ERROR * 1000.0,
        ),
        Reason::Accuracy { angle } => {
            write!(f, "a corner of {angle:.1}°: the accuracy criterion R384 limits the speed")
        }
        Reason::Overload { angle } => {
            write!(f, "a corner of {angle:.1}°: the dynamic criterion R385 limits the overload")
        }
        Reason::Centrifugal { radius } => {
            write!(f, "an arc of radius {radius:.3} mm: the centrifugal criterion limits the speed")
        }
        Reason::WindowEnd { blocks } => {
            write!(f, "the look-ahead of {blocks} blocks ends: the last block planned must be able to stop")
        }
        Reason::ContinuityLength { limit } => {
            write!(f, "a block shorter than R382 ({limit:.3} mm) breaks continuity")
        }
        Reason::Spindle { from, to } => write!(f, "the cut waits for the spindle to get from {from:.0} to {to:.0} rpm"),
    }
}
