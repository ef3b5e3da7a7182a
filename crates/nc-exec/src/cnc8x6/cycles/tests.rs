use expect_test::{Expect, expect};
use ncc_syntax::{Decimal, Sign};

use super::*;
use crate::cnc8x6::arith::literal_raw;

/// Parameters from their values as a program writes them.
fn params(values: &[(usize, &str)]) -> Parameters {
    let mut params = Parameters::zeroed();
    for &(n, text) in values {
        let (sign, digits) = match text.strip_prefix('-') {
            Some(digits) => (Some(Sign::Minus), digits),
            None => (None, text),
        };
        params.set(n, literal_raw(&Decimal::parse(sign, digits).unwrap()));
    }
    params
}

/// The milling inputs of 03 Appendix B.
const MILLING: [(usize, &str); 7] =
    [(26, "460"), (27, "1000"), (28, "12."), (29, "300"), (30, "5."), (31, "-50."), (32, "30.")];

/// The milling inputs with some replaced.
fn milling(changes: &[(usize, &str)]) -> Parameters {
    let mut values = MILLING.to_vec();
    values.retain(|(n, _)| !changes.iter().any(|(changed, _)| changed == n));
    values.extend_from_slice(changes);
    params(&values)
}

fn position(axes: &[(u8, f64)]) -> Position {
    let mut position = [0.0; 26];
    for &(letter, value) in axes {
        position[usize::from(letter - b'A')] = value;
    }
    position
}

/// A call at G90 G94 S500 M3, diameter programming.
fn call(number: u32, kind: CycleKind, params: &Parameters, at: Position) -> CycleInput<'_> {
    CycleInput {
        number,
        kind,
        params,
        position: at,
        incremental: false,
        per_revolution: false,
        speed: 500.0,
        spindle: Spindle::Clockwise,
        diameter: true,
    }
}

/// A milling call at X100 Y0 Z50, as in Appendix B.
fn mill(number: u32, params: &Parameters) -> CycleInput<'_> {
    call(number, CycleKind::Milling, params, position(&[(b'X', 100.0), (b'Z', 50.0)]))
}

fn lathe(number: u32, params: &Parameters, x: f64, z: f64) -> CycleInput<'_> {
    call(number, CycleKind::Lathe, params, position(&[(b'X', x), (b'Z', z)]))
}

fn check(input: &CycleInput<'_>, expected: Expect) {
    expected.assert_eq(&expand(input).unwrap().to_string());
}

fn error(input: &CycleInput<'_>) -> String {
    expand(input).unwrap_err().to_string()
}

fn axis(position: &Position, letter: u8) -> f64 {
    position[usize::from(letter - b'A')]
}

/// 03 §2.1.1: S := R27; rapid to RA 5, feed at R26 = 460 mm/min to RB −50,
/// rapid to RC 30; X and Y stay.
#[test]
fn milling_g81_drills_from_ra_to_rb_and_retracts_to_rc() {
    let p = params(&MILLING);
    check(
        &mill(81, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-50.000 F460 mm/min
            G00 Z30.000
        "#]],
    );
    let cycle = expand(&mill(81, &p)).unwrap();
    assert_eq!(cycle.steps[2].feed_rate(), Some(460.0));
    let end = cycle.end();
    assert_eq!([axis(&end, b'X'), axis(&end, b'Y'), axis(&end, b'Z')], [100.0, 0.0, 30.0]);
}

/// 03 §2.1.2: as G81 with the dwell R29 = 300 × 10 ms = 3 s at RB.
#[test]
fn milling_g82_dwells_at_the_bottom() {
    let p = params(&MILLING);
    let cycle = expand(&mill(82, &p)).unwrap();
    assert_eq!(cycle.steps[3], CycleStep::Dwell { seconds: 3.0 });
    check(
        &mill(82, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-50.000 F460 mm/min
            G04 3 s
            G00 Z30.000
        "#]],
    );
}

/// 03 §2.1.3 and Appendix B: pecks of 12 mm from 5 to −50 (−7, −19, −31,
/// −43, then −50 clamped), each re-approached 1 mm above the last depth;
/// the last retracts to RC.
#[test]
fn milling_g83_pecks_and_retracts_to_ra() {
    let p = params(&MILLING);
    check(
        &mill(83, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-7.000 F460 mm/min
            G00 Z5.000
            G00 Z-6.000
            G01 Z-19.000 F460 mm/min
            G00 Z5.000
            G00 Z-18.000
            G01 Z-31.000 F460 mm/min
            G00 Z5.000
            G00 Z-30.000
            G01 Z-43.000 F460 mm/min
            G00 Z5.000
            G00 Z-42.000
            G01 Z-50.000 F460 mm/min
            G00 Z30.000
        "#]],
    );
}

/// Appendix B, +Z: q = |−20|, from −50 to 0 (−30, −10, then 0 clamped), RC 10.
#[test]
fn milling_g83_drills_toward_plus_z_when_rb_is_above_ra() {
    let p = milling(&[(28, "-20."), (30, "-50."), (31, "0."), (32, "10.")]);
    let input = call(83, CycleKind::Milling, &p, position(&[(b'Z', -60.0)]));
    check(
        &input,
        expect![[r#"
            S1000
            G00 Z-50.000
            G01 Z-30.000 F460 mm/min
            G00 Z-50.000
            G00 Z-31.000
            G01 Z-10.000 F460 mm/min
            G00 Z-50.000
            G00 Z-11.000
            G01 Z0.000 F460 mm/min
            G00 Z10.000
        "#]],
    );
}

/// G83 programs no G90: under G91 from Z50 the first word Z5 moves to
/// Z55, the feed Z−7 from there to Z48 (03 §2.1.3).
#[test]
fn milling_g83_moves_incrementally_under_g91() {
    let p = params(&MILLING);
    let input = CycleInput { incremental: true, ..mill(83, &p) };
    let cycle = expand(&input).unwrap();
    let z: Vec<f64> = cycle.steps.iter().filter_map(|step| step.to()).take(3).map(|to| axis(to, b'Z')).collect();
    assert_eq!(z, [55.0, 48.0, 53.0]);
}

/// 03 §2.1.4: under G94 whatever the call's mode; M3 at the call is
/// reversed to M4 at RB.
#[test]
fn milling_g84_reverses_the_spindle_at_the_bottom() {
    let p = params(&MILLING);
    let input = CycleInput { per_revolution: true, ..mill(84, &p) };
    check(
        &input,
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-50.000 F460 mm/min
            M4
            G01 Z5.000 F460 mm/min
            G00 Z30.000
        "#]],
    );
    let input = CycleInput { spindle: Spindle::Stopped, ..mill(84, &p) };
    assert_eq!(error(&input), "G84 reverses the spindle at the hole's bottom: it needs M3 or M4 before the call");
}

/// 03 §2.1.5: feed to RB and back to RA, rapid to RC.
#[test]
fn milling_g85_retracts_at_feed() {
    let p = params(&MILLING);
    check(
        &mill(85, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-50.000 F460 mm/min
            G01 Z5.000 F460 mm/min
            G00 Z30.000
        "#]],
    );
}

/// 03 §2.1.6 and Appendix B: steps of 12 mm to −7, −19, −31, −43 with a
/// 3 s dwell after each, the rest to −50 without, rapid to 30.
#[test]
fn milling_g86_breaks_chips_with_dwells() {
    let p = params(&MILLING);
    check(
        &mill(86, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G01 Z-7.000 F460 mm/min
            G04 3 s
            G01 Z-19.000 F460 mm/min
            G04 3 s
            G01 Z-31.000 F460 mm/min
            G04 3 s
            G01 Z-43.000 F460 mm/min
            G04 3 s
            G01 Z-50.000 F460 mm/min
            G00 Z30.000
        "#]],
    );
}

/// Appendix B: an increment of 60 beyond the depth of 55 leaves the plunge
/// to RB in G00.
#[test]
fn milling_g86_with_an_increment_beyond_the_depth_plunges_at_rapid() {
    let p = milling(&[(28, "60.")]);
    check(
        &mill(86, &p),
        expect![[r#"
            S1000
            G00 Z5.000
            G00 Z-50.000
            G00 Z30.000
        "#]],
    );
}

/// 03 §2.1.7 and Appendix B: jump-off 15 in Y, intermediate plane −10.
#[test]
fn milling_g87_jumps_off_in_y() {
    let p = milling(&[(28, "15."), (29, "-10.")]);
    check(
        &mill(87, &p),
        expect![[r#"
            G00 Z5.000
            M19
            G00 Y15.000
            G00 Z-10.000
            G00 Y0.000
            M3 S1000
            G01 Z-50.000 F460 mm/min
            M19
            G00 Y15.000
            G00 Z30.000
            G00 Y0.000
        "#]],
    );
}

#[test]
fn milling_g88_and_g89_are_empty_and_the_lathe_has_neither() {
    let p = params(&MILLING);
    for number in [88, 89] {
        let cycle = expand(&mill(number, &p)).unwrap();
        assert!(cycle.steps.is_empty());
        assert_eq!(cycle.end(), cycle.start);
    }
    assert_eq!(error(&lathe(88, &p, 0.0, 0.0)), "the lathe cycle file has no G88 (the lathe cycles are G81–G87)");
    assert_eq!(error(&mill(80, &p)), "the milling cycle file has no G80");
}

/// Under G95, R26 = 200 is 200 µm/rev at the cycle's S = R27 = 1000 rpm:
/// 200 mm/min. With R27 = 0 the axes cannot move.
#[test]
fn feed_per_revolution_turns_with_the_cycle_speed() {
    let p = milling(&[(26, "200")]);
    let input = CycleInput { per_revolution: true, ..mill(81, &p) };
    let cycle = expand(&input).unwrap();
    assert_eq!(
        cycle.steps[2],
        CycleStep::Feed {
            to: position(&[(b'X', 100.0), (b'Z', -50.0)]),
            feed: FeedSpec::PerRevolution { per_rev: 0.2, speed: 1000.0 }
        }
    );
    assert_eq!(cycle.steps[2].feed_rate(), Some(200.0));
    let p = milling(&[(27, "0")]);
    let input = CycleInput { per_revolution: true, ..mill(81, &p) };
    assert_eq!(error(&input), "feed per revolution or a thread with spindle speed S0: the axes cannot move");
}

/// 03 §2.3.1, example E6 and Appendix B: 17 chips from Ø116 to Ø52, each
/// 1.678 shorter than Z−100, then two finishing passes to Zt = −70.635
/// and the face to (Ø120, Z−100).
#[test]
fn lathe_g81_roughs_example_e6() {
    let p = params(&[
        (24, "-8."),
        (25, "-4."),
        (26, "200"),
        (27, "0.002"),
        (28, "4."),
        (29, "1.678"),
        (30, "-70."),
        (31, "-100."),
    ]);
    check(
        &lathe(81, &p, 128.0, 4.0),
        expect![[r#"
            G00 X116.000
            G01 Z-98.322 F200 mm/min
            G01 X128.000 F200 mm/min
            G00 Z4.000
            G00 X112.000
            G01 Z-96.644 F200 mm/min
            G01 X116.000 F200 mm/min
            G00 Z4.000
            G00 X108.000
            G01 Z-94.966 F200 mm/min
            G01 X112.000 F200 mm/min
            G00 Z4.000
            G00 X104.000
            G01 Z-93.288 F200 mm/min
            G01 X108.000 F200 mm/min
            G00 Z4.000
            G00 X100.000
            G01 Z-91.610 F200 mm/min
            G01 X104.000 F200 mm/min
            G00 Z4.000
            G00 X96.000
            G01 Z-89.932 F200 mm/min
            G01 X100.000 F200 mm/min
            G00 Z4.000
            G00 X92.000
            G01 Z-88.254 F200 mm/min
            G01 X96.000 F200 mm/min
            G00 Z4.000
            G00 X88.000
            G01 Z-86.576 F200 mm/min
            G01 X92.000 F200 mm/min
            G00 Z4.000
            G00 X84.000
            G01 Z-84.898 F200 mm/min
            G01 X88.000 F200 mm/min
            G00 Z4.000
            G00 X80.000
            G01 Z-83.220 F200 mm/min
            G01 X84.000 F200 mm/min
            G00 Z4.000
            G00 X76.000
            G01 Z-81.542 F200 mm/min
            G01 X80.000 F200 mm/min
            G00 Z4.000
            G00 X72.000
            G01 Z-79.864 F200 mm/min
            G01 X76.000 F200 mm/min
            G00 Z4.000
            G00 X68.000
            G01 Z-78.186 F200 mm/min
            G01 X72.000 F200 mm/min
            G00 Z4.000
            G00 X64.000
            G01 Z-76.508 F200 mm/min
            G01 X68.000 F200 mm/min
            G00 Z4.000
            G00 X60.000
            G01 Z-74.830 F200 mm/min
            G01 X64.000 F200 mm/min
            G00 Z4.000
            G00 X56.000
            G01 Z-73.152 F200 mm/min
            G01 X60.000 F200 mm/min
            G00 Z4.000
            G00 X52.000
            G01 Z-71.474 F200 mm/min
            G01 X56.000 F200 mm/min
            G00 Z4.000
            G00 X50.000
            G01 Z-70.635 F200 mm/min
            G01 X120.000 Z-100.000 F200 mm/min
            G01 X128.000 F200 mm/min
            G00 Z4.000
            G00 X50.000
            G01 Z-70.635 F200 mm/min
            G01 X120.000 Z-100.000 F200 mm/min
            G01 X128.000 F200 mm/min
            G00 Z4.000
        "#]],
    );
}

/// From X50 Z2: Xs = 48, Xe = 43, Ze = −20, chips of 2 (ceil(5/2) − 1 = 2
/// chips at 46 and 44, since 42 is past 43), then the last chip at 43
/// back to X50, without finishing (R27 = 0).
#[test]
fn lathe_g81_without_finishing_cuts_a_last_chip() {
    let p = params(&[(24, "-2."), (25, "-2."), (26, "100"), (28, "2."), (30, "-5."), (31, "-20.")]);
    check(
        &lathe(81, &p, 50.0, 2.0),
        expect![[r#"
            G00 X46.000
            G01 Z-20.000 F100 mm/min
            G01 X50.000 F100 mm/min
            G00 Z2.000
            G00 X44.000
            G01 Z-20.000 F100 mm/min
            G01 X46.000 F100 mm/min
            G00 Z2.000
            G00 X43.000
            G01 Z-20.000 F100 mm/min
            G01 X50.000 F100 mm/min
            G00 Z2.000
        "#]],
    );
}

/// 03 §2.3.2 and Appendix B, with the file's swapped X/Z at the end.
#[test]
fn lathe_g82_faces_and_ends_as_its_file_does() {
    let p = params(&[
        (24, "-4."),
        (25, "-2."),
        (26, "200"),
        (27, "0.001"),
        (28, "3."),
        (29, "2."),
        (30, "-40."),
        (31, "-10."),
    ]);
    check(
        &lathe(82, &p, 104.0, 2.0),
        expect![[r#"
            G01 Z-3.000 F200 mm/min
            G01 X62.000 F200 mm/min
            G01 Z2.000 F200 mm/min
            G00 X104.000
            G01 Z-6.000 F200 mm/min
            G01 X64.000 F200 mm/min
            G01 Z-3.000 F200 mm/min
            G00 X104.000
            G01 Z-9.000 F200 mm/min
            G01 X66.000 F200 mm/min
            G01 Z-6.000 F200 mm/min
            G00 X104.000
            G01 Z-10.000 F200 mm/min
            G01 X66.667 F200 mm/min
            G01 X60.000 Z0.000 F200 mm/min
            G01 Z104.000 F200 mm/min
            G00 X2.000
        "#]],
    );
}

/// 03 §2.3.3 and Appendix B: every peck retracts to RA, no S.
#[test]
fn lathe_g83_retracts_to_ra_after_every_peck() {
    let p = params(&[(26, "100"), (28, "20."), (30, "2."), (31, "-50.")]);
    check(
        &lathe(83, &p, 0.0, 10.0),
        expect![[r#"
            G00 Z2.000
            G01 Z-18.000 F100 mm/min
            G00 Z2.000
            G00 Z-17.000
            G01 Z-38.000 F100 mm/min
            G00 Z2.000
            G00 Z-37.000
            G01 Z-50.000 F100 mm/min
            G00 Z2.000
        "#]],
    );
    let p = params(&[(26, "100"), (28, "-20."), (30, "2."), (31, "-50.")]);
    assert_eq!(
        error(&lathe(83, &p, 0.0, 10.0)),
        "R28 = -20.000: the increment must be above 0: the lathe cycle takes it as written"
    );
}

/// The thread of Appendix B: Ø26 Z3, depth Ø1.84 in 5 chips of quotient 0.8.
const THREAD: [(usize, &str); 10] = [
    (21, "0"),
    (23, "1"),
    (24, "-2."),
    (25, "-3."),
    (26, "1.5"),
    (27, "0"),
    (28, "0.8"),
    (29, "5"),
    (30, "-1.840"),
    (31, "-30."),
];

fn thread(changes: &[(usize, &str)]) -> Parameters {
    let mut values = THREAD.to_vec();
    values.retain(|(n, _)| !changes.iter().any(|(changed, _)| changed == n));
    values.extend_from_slice(changes);
    params(&values)
}

/// 03 §2.3.4 and Appendix B: 1 + 0.8 + … + 0.8⁴ = 3.362, first chip
/// 1.840 / 3.362 = 0.547 → X23.453, then 0.438, 0.350, 0.280; R23 + 1 = 2
/// passes at Xe = 22.160. The lead is 1.5 mm at S500: 750 mm/min.
#[test]
fn lathe_g84_radial_infeed() {
    let p = thread(&[]);
    check(
        &lathe(84, &p, 26.0, 3.0),
        expect![[r#"
            G00 X23.453
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X23.015
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.665
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.385
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
        "#]],
    );
    let cycle = expand(&lathe(84, &p, 26.0, 3.0)).unwrap();
    assert_eq!(cycle.steps[1].feed_rate(), Some(750.0));
}

/// Appendix B: six chips, alternating for R29 − R21 = 4 depths. First
/// depth 0.499 (Ø), radial 0.250 after the shift: P = (51 − 13.857) / 96
/// = 0.387, less the allowance 0.05: starts at Z3 ∓ 0.337.
#[test]
fn lathe_g84_alternating_infeed() {
    let p = thread(&[(19, "0.05"), (21, "2"), (29, "6")]);
    let cycle = expand(&lathe(84, &p, 26.0, 3.0)).unwrap();
    let approaches: Vec<(f64, f64)> = cycle
        .steps
        .iter()
        .filter_map(|step| match step {
            CycleStep::Rapid { to } if axis(to, b'X') != 26.0 => Some((axis(to, b'X'), axis(to, b'Z'))),
            _ => None,
        })
        .collect();
    let expected = [
        (23.501, 2.663),
        (23.501, 3.337),
        (23.102, 2.778),
        (23.102, 3.222),
        (22.783, 2.870),
        (22.783, 3.130),
        (22.528, 2.944),
        (22.528, 3.056),
        (22.324, 3.0),
        (22.160, 3.0),
        (22.160, 3.0),
    ];
    assert_eq!(approaches, expected);
    check(
        &lathe(84, &p, 26.0, 3.0),
        expect![[r#"
            G00 X23.501 Z2.663
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X23.501 Z3.337
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X23.102 Z2.778
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X23.102 Z3.222
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.783 Z2.870
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.783 Z3.130
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.528 Z2.944
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.528 Z3.056
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.324
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
        "#]],
    );
}

/// 03 §2.3.5: G84's passes with the run-out J = R22 on every thread. Two
/// chips: 1.840 / (1 + 0.8) = 1.022 → X22.978, then one pass at 22.160
/// (R23 = 0).
#[test]
fn lathe_g85_cuts_with_run_out() {
    let p = thread(&[(22, "2."), (29, "2"), (23, "0")]);
    check(
        &lathe(85, &p, 26.0, 3.0),
        expect![[r#"
            G00 X22.978
            G33 Z-30.000 F1.5 mm/rev S500 J2
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 Z-30.000 F1.5 mm/rev S500 J2
            G00 X26.000
            G00 Z3.000
        "#]],
    );
    let p = thread(&[(22, "0")]);
    assert_eq!(error(&lathe(85, &p, 26.0, 3.0)), "R22 = 0.000: the run-out length must be above 0");
}

/// 03 §2.3.6 and Appendix B: from X50 Z2, corner (46, 0), chamfer 3 × 3 in
/// chips of 1: A = B = 6, so the passes reach 7, 8, 9 and 9 again (3 is a
/// multiple of 1).
#[test]
fn lathe_g86_cuts_a_chamfer() {
    let p = params(&[(24, "-4."), (25, "-2."), (26, "100"), (28, "1."), (30, "3."), (31, "-3.")]);
    check(
        &lathe(86, &p, 50.0, 2.0),
        expect![[r#"
            G00 X43.000
            G01 X50.000 Z-5.000 F100 mm/min
            G00 Z2.000
            G00 X42.000
            G01 X50.000 Z-6.000 F100 mm/min
            G00 Z2.000
            G00 X41.000
            G01 X50.000 Z-7.000 F100 mm/min
            G00 Z2.000
            G00 X41.000
            G01 X50.000 Z-7.000 F100 mm/min
            G00 Z2.000
        "#]],
    );
    let p = params(&[(24, "-4."), (25, "-2."), (26, "100"), (28, "1."), (30, "0"), (31, "-3.")]);
    assert_eq!(error(&lathe(86, &p, 50.0, 2.0)), "R30 = 0.000: the chamfer's X length must not be 0");
}

/// 03 §2.3.7 and Appendix B: sum 2.44, first chip 0.754, second 0.603,
/// each pass rising by R22 = 4; one final pass (R23 = 0).
#[test]
fn lathe_g87_cuts_a_taper_thread() {
    let p = thread(&[(22, "4."), (23, "0"), (29, "3")]);
    check(
        &lathe(87, &p, 26.0, 3.0),
        expect![[r#"
            G00 X23.246
            G33 X27.246 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.643
            G33 X26.643 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
            G00 X22.160
            G33 X26.160 Z-30.000 F1.5 mm/rev S500
            G00 X26.000
            G00 Z3.000
        "#]],
    );
}

#[test]
fn thread_parameters_are_checked() {
    for (changes, message) in [
        (&[(26, "0")][..], "R26 = 0.000: the thread lead must be above 0"),
        (&[(28, "1.")], "R28 = 1.000: the chip quotient must lie between 0 and 1"),
        (&[(29, "1")], "R29 = 0.001: a thread needs at least 2 chips"),
        (
            &[(29, "10.002")],
            "the cycle would repeat a section 10001 times; the supplied cycle's jump stops after 10000",
        ),
    ] {
        assert_eq!(error(&lathe(84, &thread(changes), 26.0, 3.0)), message);
    }
    let p = thread(&[]);
    let input = CycleInput { speed: 0.0, ..lathe(87, &p, 26.0, 3.0) };
    assert_eq!(error(&input), "feed per revolution or a thread with spindle speed S0: the axes cannot move");
}

#[test]
fn errors_name_the_parameter() {
    let p = milling(&[(28, "0")]);
    assert_eq!(error(&mill(83, &p)), "R28 = 0.000: the increment must not be 0: the pecks would never reach RB");
    // Depth 0 ends before the increment matters.
    let p = milling(&[(28, "0"), (31, "5.")]);
    assert_eq!(expand(&mill(83, &p)).unwrap().to_string(), "S1000\n");
    // 55 mm in pecks of 1 µm.
    let p = milling(&[(28, "1")]);
    assert_eq!(
        error(&mill(83, &p)),
        "the cycle would repeat a section 55000 times; the supplied cycle's jump stops after 9999"
    );
    let p = milling(&[(29, "100.")]);
    assert_eq!(error(&mill(86, &p)), "R29 = 100.000: the dwell must lie between 0 and 9999 (× 10 ms)");
    let p = milling(&[(26, "0")]);
    assert_eq!(error(&mill(81, &p)), "R26 = 0.000: the feed must be above 0");
    let p = milling(&[(30, "99999.")]);
    assert_eq!(error(&mill(81, &p)), "R30 = 99999.000: a parameter holds at most ±69999.999");
    let p = Parameters::unknown();
    assert_eq!(error(&mill(81, &p)), "the cycle needs R27, whose value is not known");
    let p = params(&[(26, "100"), (28, "0"), (30, "-5."), (31, "-20.")]);
    assert_eq!(
        error(&lathe(81, &p, 50.0, 2.0)),
        "R28 = 0.000: the chip thickness must be above 0 (the cycle gives it the region's direction itself)"
    );
    let p = params(&MILLING);
    let input = CycleInput { position: position(&[(b'Z', f64::NAN)]), ..mill(81, &p) };
    assert_eq!(error(&input), "the Z position is outside ±69999.999 mm, which the cycle's parameters cannot hold");
}

#[test]
fn the_cycle_file_names_the_kind() {
    for (file, kind) in [
        (None, CycleKind::Milling),
        (Some("PCYKLYDG.NCP"), CycleKind::Milling),
        (Some("PEVNECYK.NCP"), CycleKind::Milling),
        (Some("PEVNECY5.NCP"), CycleKind::Lathe),
        (Some("cycles/pevnecy6.ncp"), CycleKind::Lathe),
        (Some("PEVNECY"), CycleKind::Milling),
    ] {
        assert_eq!(CycleKind::of(file), kind, "{file:?}");
    }
}
