//! The Haas lathe's canned cycles against numbers worked out by hand from
//! the lathe manual's rules (§6) and the executor's documented
//! assumptions, and the manual's example programs run to their end.

use std::{collections::BTreeMap, f64::consts::PI};

use nc_exec::{
    haas_lathe::cycles::{ThreadMethod, thread_depths},
    machine::MachineConfig,
    run::{self as runner, Motion, NoFiles, Path, RunRule, Step, Stop, Trace},
};
use ncc_catalog::Dialect;

/// A Haas lathe with the given Settings (machine constants, in
/// thousandths).
fn lathe(settings: &[(u32, i64)]) -> MachineConfig {
    let constants = settings.iter().copied().collect::<BTreeMap<_, _>>();
    MachineConfig { constants, ..MachineConfig::of_control(Dialect::HaasLathe) }
}

fn run(text: &str, machine: &MachineConfig, budget: usize) -> Trace {
    runner::run(text, &NoFiles, machine, budget)
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-6, "{actual} is not {expected}");
}

/// (Z, X radius) of a step's end; the lathe's axes are X then Z.
fn end(step: &Step) -> [f64; 2] {
    [step.end[1], step.end[0]]
}

fn close_point(actual: [f64; 2], expected: [f64; 2]) {
    assert!(
        (actual[0] - expected[0]).abs() < 1e-6 && (actual[1] - expected[1]).abs() < 1e-6,
        "{actual:?} is not {expected:?}"
    );
}

/// The steps of the block whose text is `line`.
fn steps_of<'t>(trace: &'t Trace, text: &str, line: &str) -> Vec<&'t Step> {
    trace.steps.iter().filter(|step| text[step.range].trim() == line).collect()
}

fn moves<'t>(steps: &[&'t Step], motion: Motion) -> Vec<&'t Step> {
    steps.iter().copied().filter(|step| step.motion == motion).collect()
}

fn no_findings(trace: &Trace) {
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

#[test]
fn g71_type_i_roughs_a_cylinder_step_in_levels_d_apart() {
    // Ø60 stock from Z2, a Ø40 step 30 long, then the shoulder out past the
    // stock; 1000 rpm at 0.3 mm/rev is 300 mm/min. Setting 73 lifts 0.5.
    let text =
        "O1\nG97 S1000 M03\nG00 X60. Z2.\nG71 P10 Q20 U0.5 W0.1 D2. F0.3\nN10 G00 X40.\nG01 Z-30.\nN20 X62.\nM30\n";
    let trace = run(text, &lathe(&[(73, 500)]), 1000);
    no_findings(&trace);
    let cycle = steps_of(&trace, text, "G71 P10 Q20 U0.5 W0.1 D2. F0.3");
    // The start point shifted by U/2 and W: (2.1, 30.25); the contour by
    // the same: its floor is the radius 20 + 0.25.
    let (top, floor, depth): (f64, f64, f64) = (30.25, 20.25, 2.0);
    let levels = ((top - floor) / depth).ceil() as usize - 1;
    assert_eq!(levels, 4);
    let feeds = moves(&cycle, Motion::Feed);
    // Each level cuts from Z2.1 to the shoulder at Z-30 + 0.1.
    for (k, cut) in feeds[..levels].iter().enumerate() {
        close_point(end(cut), [-29.9, top - depth * (k + 1) as f64]);
        close(cut.length, 2.1 + 29.9);
    }
    // Then one pass along the contour shifted by U/2 and W, the last cut:
    // along Ø40.5 to the shoulder and up it to Ø62.5.
    assert_eq!(feeds.len(), levels + 2);
    close_point(end(feeds[levels]), [-29.9, 20.25]);
    close_point(end(feeds[levels + 1]), [-29.9, 31.25]);
    let cut_length = levels as f64 * 32.0 + 32.0 + 11.0;
    let cut: f64 = feeds.iter().map(|step| step.length).sum();
    close(cut, cut_length);
    let time: f64 = feeds.iter().map(|step| step.duration).sum();
    close(time, cut_length / (0.3 * 1000.0) * 60.0);
    // After each cut: lift 0.5 at 45°, back to Z2.1 at rapid.
    let rapids = moves(&cycle, Motion::Rapid);
    close_point(end(rapids[0]), [2.1, 30.25]);
    close_point(end(rapids[1]), [2.1, 28.25]);
    close_point(end(rapids[2]), [-29.4, 28.75]);
    close_point(end(rapids[3]), [2.1, 28.75]);
    // Back to the start: Ø60 is smaller than Q's Ø62, so Z first.
    let last: Vec<[f64; 2]> = cycle[cycle.len() - 2..].iter().map(|step| end(step)).collect();
    close_point(last[0], [2.0, 31.25]);
    close_point(last[1], [2.0, 30.0]);
    // The run goes on after the Q block.
    assert_eq!(text[trace.steps.last().unwrap().range].trim(), "M30");
}

#[test]
fn g71_with_i_and_k_adds_a_pass_and_stops_the_levels_there() {
    let text = "O1\nG97 S1000 M03\nG00 X60. Z2.\nG71 P10 Q20 U0.5 W0.1 D2. I0.5 K0.2 F0.3\nN10 G00 X40.\nG01 Z-30.\nN20 X62.\nM30\n";
    let trace = run(text, &lathe(&[(73, 500)]), 1000);
    no_findings(&trace);
    let cycle = steps_of(&trace, text, "G71 P10 Q20 U0.5 W0.1 D2. I0.5 K0.2 F0.3");
    // Shifted by U/2 + I = 0.75 and W + K = 0.3: from 30.75 down to 20.75.
    let feeds = moves(&cycle, Motion::Feed);
    for (k, cut) in feeds[..4].iter().enumerate() {
        close_point(end(cut), [-29.7, 30.75 - 2.0 * (k + 1) as f64]);
    }
    // Along the contour at (0.3, 0.75), then at (0.1, 0.25).
    let passes: Vec<[f64; 2]> = feeds[4..].iter().map(|step| end(step)).collect();
    let expected = [[-29.7, 20.75], [-29.7, 31.75], [-29.9, 20.25], [-29.9, 31.25]];
    assert_eq!(passes.len(), expected.len());
    for (pass, expected) in passes.into_iter().zip(expected) {
        close_point(pass, expected);
    }
}

#[test]
fn g71_type_ii_follows_the_contour_up_to_the_level_above() {
    // The P block programs X and Z: Type II. A taper from Ø40 at Z-10 to
    // Ø50 at Z-20, then out.
    let text = "O1\nG97 S1000 M03\nG00 X60. Z2.\nG71 P10 Q20 U0 W0 D3. F0.3\nN10 G00 X40. Z2.\nG01 Z-10.\nX50. Z-20.\nN20 X62.\nM30\n";
    let trace = run(text, &lathe(&[(73, 0)]), 1000);
    no_findings(&trace);
    let cycle = steps_of(&trace, text, "G71 P10 Q20 U0 W0 D3. F0.3");
    let feeds: Vec<[f64; 2]> = moves(&cycle, Motion::Feed).iter().map(|step| end(step)).collect();
    // Levels 27 and 24 (30 − 3k above the floor 20; 21 too). At 27 the
    // cut ends where the shoulder rises, Z-20, and follows it up to 30.
    close_point(feeds[0], [-20.0, 27.0]);
    close_point(feeds[1], [-20.0, 30.0]);
    // At 24: to the taper's 24 (Z-18), up the taper to 25 (Z-20), up the
    // shoulder to 27, the level above.
    close_point(feeds[2], [-18.0, 24.0]);
    close_point(feeds[3], [-20.0, 25.0]);
    close_point(feeds[4], [-20.0, 27.0]);
    // At 21: to the taper's 21 (Z-12), up the taper to 24 (Z-18).
    close_point(feeds[5], [-12.0, 21.0]);
    close_point(feeds[6], [-18.0, 24.0]);
    // Then the pass along the contour.
    let along = [[-10.0, 20.0], [-20.0, 25.0], [-20.0, 31.0]];
    assert_eq!(feeds.len(), 7 + along.len());
    for (actual, expected) in feeds[7..].iter().zip(along) {
        close_point(*actual, expected);
    }
}

#[test]
fn g72_faces_in_levels_d_apart_in_z() {
    // A Ø40 stub 12 long faced out of Ø80 stock from Z2.
    let text =
        "O1\nG97 S500 M03\nG00 X82. Z2.\nG72 P10 Q20 U0.4 W0.2 D3. F0.25\nN10 G00 Z-12.\nG01 X40.\nN20 Z2.\nM30\n";
    let trace = run(text, &lathe(&[(73, 500)]), 1000);
    no_findings(&trace);
    let cycle = steps_of(&trace, text, "G72 P10 Q20 U0.4 W0.2 D3. F0.25");
    // Shifted by W = 0.2 in Z and U/2 = 0.2 in X: start Z2.2, floor Z-11.8.
    let (top, floor, depth): (f64, f64, f64) = (2.2, -11.8, 3.0);
    let levels = ((top - floor) / depth).ceil() as usize - 1;
    assert_eq!(levels, 4);
    let feeds = moves(&cycle, Motion::Feed);
    for (k, cut) in feeds[..levels].iter().enumerate() {
        // From the shifted start radius 41.2 in to the stub's 20.2.
        close_point(end(cut), [top - depth * (k + 1) as f64, 20.2]);
        close(cut.length, 41.2 - 20.2);
    }
    // Then along the shifted contour: in at Z-11.8 to 20.2, out to Z2.2.
    close_point(end(feeds[levels]), [-11.8, 20.2]);
    close_point(end(feeds[levels + 1]), [2.2, 20.2]);
    assert_eq!(feeds.len(), levels + 2);
    // Ø82 is not smaller than Q's Ø40: back X first, then Z.
    let last: Vec<[f64; 2]> = cycle[cycle.len() - 2..].iter().map(|step| end(step)).collect();
    close_point(last[0], [2.2, 41.0]);
    close_point(last[1], [2.0, 41.0]);
}

#[test]
fn g73_runs_the_contour_d_times_sharing_i_and_k() {
    let text = "O1\nG97 S500 M03\nG00 X80. Z5.\nG73 P10 Q20 U0.4 W0.2 I6. K3. D3. F0.25\nN10 G00 X20. Z0.\nG01 Z-20.\nN20 X80.\nM30\n";
    let trace = run(text, &lathe(&[]), 1000);
    no_findings(&trace);
    let cycle = steps_of(&trace, text, "G73 P10 Q20 U0.4 W0.2 I6. K3. D3. F0.25");
    let feeds: Vec<[f64; 2]> = moves(&cycle, Motion::Feed).iter().map(|step| end(step)).collect();
    // Three passes: I and K shared as 1, 1/2, 0 on top of U/2 and W.
    assert_eq!(feeds.len(), 3 * 2);
    for (pass, share) in [1.0, 0.5, 0.0].into_iter().enumerate() {
        let (dz, dx) = (0.2 + 3.0 * share, 0.2 + 6.0 * share);
        close_point(feeds[2 * pass], [-20.0 + dz, 10.0 + dx]);
        close_point(feeds[2 * pass + 1], [-20.0 + dz, 40.0 + dx]);
    }
    // Each pass starts with the P block's rapid to its shifted point.
    let entries: Vec<[f64; 2]> =
        moves(&cycle, Motion::Rapid).iter().map(|step| end(step)).filter(|point| point[1] < 20.0).collect();
    assert_eq!(entries.len(), 3);
    close_point(entries[0], [3.2, 16.2]);
}

#[test]
fn g70_follows_the_contour_as_programmed() {
    let text = include_str!("../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc");
    let trace = run(text, &lathe(&[]), 10_000);
    let finishing = steps_of(&trace, text, "G70 P10 Q20 F0.1");
    let ends: Vec<[f64; 2]> = finishing.iter().map(|step| end(step)).collect();
    // P1 … P10 of the manual's figure, radii, from the start Ø70 Z3, then
    // back: Ø70 is smaller than Q's Ø74, so Z first.
    let contour = [
        [3.0, 8.5],
        [0.0, 8.5],
        [-15.0, 14.0],
        [-23.0, 14.0],
        [-31.0, 22.0],
        [-39.0, 22.0],
        [-47.0, 30.0],
        [-60.0, 30.0],
        [-65.0, 35.0],
        [-65.0, 37.0],
        [3.0, 37.0],
        [3.0, 35.0],
    ];
    assert_eq!(ends.len(), contour.len());
    for (actual, expected) in ends.into_iter().zip(contour) {
        close_point(actual, expected);
    }
    // The arcs keep their centres and turn as programmed: G02 R8 about
    // (Z-23, r22), G03 R8 about (Z-47, r22).
    assert_eq!(finishing[4].path, Path::Arc { plane: (b'Z', b'X'), centre: [-23.0, 22.0], clockwise: true });
    assert_eq!(finishing[6].path, Path::Arc { plane: (b'Z', b'X'), centre: [-47.0, 22.0], clockwise: false });
    let length: f64 = moves(&finishing, Motion::Feed).iter().map(|step| step.length).sum();
    let quarter = 8.0 * PI / 2.0;
    close(length, 3.0 + 15f64.hypot(5.5) + 8.0 + quarter + 8.0 + quarter + 13.0 + 50f64.sqrt());
}

#[test]
fn g90_is_a_box_from_the_start_point_repeated_by_x() {
    // 500 rpm at 0.3 mm/rev: 150 mm/min.
    let text = "O1\nG97 S500 M03\nG00 X52. Z3.\nG90 X45. Z-30. F0.3\nX40.\nX40. I-2.\nM30\n";
    let trace = run(text, &lathe(&[]), 1000);
    no_findings(&trace);
    let first = steps_of(&trace, text, "G90 X45. Z-30. F0.3");
    let ends: Vec<[f64; 2]> = first.iter().map(|step| end(step)).collect();
    assert_eq!(ends, [[3.0, 22.5], [-30.0, 22.5], [-30.0, 26.0], [3.0, 26.0]]);
    let kinds: Vec<Motion> = first.iter().map(|step| step.motion).collect();
    assert_eq!(kinds, [Motion::Rapid, Motion::Feed, Motion::Feed, Motion::Rapid]);
    close(first[1].duration + first[2].duration, (33.0 + 3.5) / (0.3 * 500.0) * 60.0);
    // The next block keeps Z-30 and cuts from the same start point.
    let second: Vec<[f64; 2]> = steps_of(&trace, text, "X40.").iter().map(|step| end(step)).collect();
    assert_eq!(second, [[3.0, 20.0], [-30.0, 20.0], [-30.0, 26.0], [3.0, 26.0]]);
    // I: the start side's radius less the end's.
    let taper = steps_of(&trace, text, "X40. I-2.");
    close_point(end(taper[0]), [3.0, 18.0]);
    close(taper[1].length, 33f64.hypot(2.0));
}

#[test]
fn g92_threads_at_one_lead_per_revolution_and_returns() {
    let text = "O1\nG97 S1500 M03\nG00 X40. Z3.\nG92 X30. Z-43. F3.5\nX29.\nM23\nX28.2\nM30\n";
    let trace = run(text, &lathe(&[(95, 1000), (96, 45_000)]), 1000);
    no_findings(&trace);
    let pass = steps_of(&trace, text, "G92 X30. Z-43. F3.5");
    let ends: Vec<[f64; 2]> = pass.iter().map(|step| end(step)).collect();
    assert_eq!(ends, [[3.0, 15.0], [-43.0, 15.0], [-43.0, 20.0], [3.0, 20.0]]);
    assert_eq!(pass[1].path, Path::Thread { lead: 3.5, speed: 1500.0 });
    // 46 mm at 3.5 mm × 1500 rpm; in and out at rapid.
    close(pass[1].duration, 46.0 / (3.5 * 1500.0) * 60.0);
    assert_eq!([pass[0].motion, pass[2].motion, pass[3].motion], [Motion::Rapid; 3]);
    // With M23 the thread stops one lead (Setting 95 = 1) short of Z-43
    // and pulls out over it at 45°.
    let chamfered: Vec<[f64; 2]> = steps_of(&trace, text, "X28.2").iter().map(|step| end(step)).collect();
    close_point(chamfered[1], [-39.5, 14.1]);
    close_point(chamfered[2], [-43.0, 17.6]);
}

#[test]
fn the_manual_s_g92_example_cuts_one_pass_a_block() {
    let text = include_str!("../../syntax/test_data/haas-lathe/e20_g92_thread.nc");
    let trace = run(text, &lathe(&[]), 1000);
    let threads: Vec<&Step> = trace.steps.iter().filter(|step| matches!(step.path, Path::Thread { .. })).collect();
    let radii: Vec<f64> = threads.iter().map(|step| step.end[0]).collect();
    let expected = [30.0, 29.0, 28.2, 27.6, 27.0, 27.0, 26.5, 25.8, 25.71].map(|diameter| diameter / 2.0);
    assert_eq!(radii.len(), expected.len());
    for (radius, expected) in radii.into_iter().zip(expected) {
        close(radius, expected);
    }
}

#[test]
fn g94_faces_as_a_box() {
    // 500 rpm at 0.2 mm/rev: 100 mm/min.
    let text = "O1\nG97 S500 M03\nG00 X52. Z3.\nG94 X20. Z-2. F0.2\nZ-4. K1.\nM30\n";
    let trace = run(text, &lathe(&[]), 1000);
    no_findings(&trace);
    let face = steps_of(&trace, text, "G94 X20. Z-2. F0.2");
    let ends: Vec<[f64; 2]> = face.iter().map(|step| end(step)).collect();
    assert_eq!(ends, [[-2.0, 26.0], [-2.0, 10.0], [3.0, 10.0], [3.0, 26.0]]);
    close(face[1].duration + face[2].duration, (16.0 + 5.0) / (0.2 * 500.0) * 60.0);
    // X20 kept; K: the face's Z at the start X less its Z at X.
    let taper: Vec<[f64; 2]> = steps_of(&trace, text, "Z-4. K1.").iter().map(|step| end(step)).collect();
    assert_eq!(taper, [[-3.0, 26.0], [-4.0, 10.0], [3.0, 10.0], [3.0, 26.0]]);
}

#[test]
fn g76_passes_deepen_by_the_square_root_law_to_the_thread_height() {
    // M30×2: root Ø27.546, height 1.227, first pass 0.3; the last pass of
    // Setting 86 = 0.1, at least Setting 99 = 0.02 deeper each pass.
    let text = "O1\nG97 S1000 M03\nG00 X32. Z5.\nG76 X27.546 Z-30. K1.227 D0.3 A60 P2 F2.\nM30\n";
    let trace = run(text, &lathe(&[(86, 100), (99, 20)]), 1000);
    no_findings(&trace);
    let (height, first, finish) = (1.227, 0.3, 0.1);
    let mut expected: Vec<f64> =
        (1..).map(|n: i32| first * f64::from(n).sqrt()).take_while(|&depth| depth < height - finish).collect();
    // No √n step is under 0.02 before 1.127.
    assert!(expected.windows(2).all(|pair| pair[1] - pair[0] > 0.02));
    expected.extend([height - finish, height]);
    assert_eq!(expected.len(), 16);
    let steps = steps_of(&trace, text, "G76 X27.546 Z-30. K1.227 D0.3 A60 P2 F2.");
    let threads: Vec<&Step> = steps.iter().copied().filter(|step| matches!(step.path, Path::Thread { .. })).collect();
    assert_eq!(threads.len(), expected.len());
    // The crest is the root plus the height: radius 15; each pass ends at
    // Z-30, the crest less its depth, radially (P2) from Z5.
    let crest = 27.546 / 2.0 + height;
    for (thread, depth) in threads.iter().zip(&expected) {
        close_point(end(thread), [-30.0, crest - depth]);
        close(thread.length, 35.0);
        close(thread.duration, 35.0 / (2.0 * 1000.0) * 60.0);
    }
    // Each pass: in at rapid, the thread, out to Ø32, back to Z5.
    let pass: Vec<[f64; 2]> = steps[..4].iter().map(|step| end(step)).collect();
    close_point(pass[0], [5.0, crest - first]);
    close_point(pass[2], [-30.0, 16.0]);
    close_point(pass[3], [5.0, 16.0]);
    close_point(end(steps.last().unwrap()), [5.0, 16.0]);
}

#[test]
fn g76_depths_and_the_flank_infeed() {
    let radial = ThreadMethod::of(Some(2.0)).unwrap();
    // Without Setting 86 the √n passes end at the height itself.
    let same = |actual: Vec<f64>, expected: &[f64]| {
        assert_eq!(actual.len(), expected.len(), "{actual:?}");
        actual.iter().zip(expected).for_each(|(actual, expected)| close(*actual, *expected));
    };
    same(thread_depths(1.0, 0.5, radial, 0.0, 0.0).unwrap(), &[0.5, 0.5 * 2f64.sqrt(), 0.5 * 3f64.sqrt(), 1.0]);
    // Constant depth (P4), and the smallest step of Setting 99.
    let constant = ThreadMethod::of(Some(4.0)).unwrap();
    same(thread_depths(1.0, 0.3, constant, 0.0, 0.0).unwrap(), &[0.3, 0.6, 0.9, 1.0]);
    same(thread_depths(1.0, 0.5, radial, 0.25, 0.0).unwrap(), &[0.5, 0.75, 1.0]);
    // A zero or missing depth, and a method beyond P4, are refused.
    assert!(thread_depths(1.0, 0.0, radial, 0.0, 0.0).is_err());
    assert!(thread_depths(0.0, 0.3, radial, 0.0, 0.0).is_err());
    assert!(ThreadMethod::of(Some(5.0)).is_err());
    // P1 goes in along the flank: each pass starts its depth × tan(A/2)
    // further along the thread.
    let text = "O1\nG97 S1000 M03\nG00 X32. Z5.\nG76 X28. Z-30. K1. D0.5 A60 P1 F2.\nM30\n";
    let trace = run(text, &lathe(&[(86, 0), (99, 0)]), 1000);
    no_findings(&trace);
    let steps = steps_of(&trace, text, "G76 X28. Z-30. K1. D0.5 A60 P1 F2.");
    let entries: Vec<[f64; 2]> =
        steps.windows(2).filter(|pair| matches!(pair[1].path, Path::Thread { .. })).map(|pair| end(pair[0])).collect();
    let tan = (30f64).to_radians().tan();
    for (entry, depth) in entries.iter().zip([0.5, 0.5 * 2f64.sqrt(), 0.5 * 3f64.sqrt(), 1.0]) {
        close_point(*entry, [5.0 - depth * tan, 15.0 - depth]);
    }
}

#[test]
fn g32_threads_along_its_line_without_returning() {
    let text = "O1\nG97 S1200 M03\nG00 X16.93 Z3.\nG32 Z-20. F2.\nX25. Z-35.\nG00 X40.\nM30\n";
    let trace = run(text, &lathe(&[]), 1000);
    no_findings(&trace);
    let cylinder = &steps_of(&trace, text, "G32 Z-20. F2.")[0];
    assert_eq!(cylinder.path, Path::Thread { lead: 2.0, speed: 1200.0 });
    close(cylinder.duration, 23.0 / (2.0 * 1200.0) * 60.0);
    let cone = &steps_of(&trace, text, "X25. Z-35.")[0];
    close_point(end(cone), [-35.0, 12.5]);
    close(cone.length, 15f64.hypot(12.5 - 16.93 / 2.0));
}

#[test]
fn constant_cutting_speed_is_held_to_the_g50_limit_along_a_facing_move() {
    // 100 m/min: k = 100000/2π rpm·mm; under 2000 rpm at radius k/2000.
    let (k, limit, feed) = (100_000.0 / (2.0 * PI), 2000.0, 0.1);
    let clamp: f64 = k / limit;
    // Wholly under the clamp radius: the limit all the way.
    let text = "O1\nG50 S2000\nG96 S100 M03\nG00 X10. Z0\nG01 X0. F0.1\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    close(steps_of(&trace, text, "G01 X0. F0.1")[0].duration, 5.0 / (feed * limit) * 60.0);
    // From radius 20: the rpm rises as 1/r down to the clamp radius, then
    // holds. Time = ∫ dr / (F·rpm) = ((20² − c²)/(2k) + c/limit) / F.
    let text = "O1\nG50 S2000\nG96 S100 M03\nG00 X40. Z0\nG01 X0. F0.1\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    let minutes = ((400.0 - clamp * clamp) / (2.0 * k) + clamp / limit) / feed;
    close(steps_of(&trace, text, "G01 X0. F0.1")[0].duration, minutes * 60.0);
}

#[test]
fn g81_drills_from_the_r_plane_and_returns_to_it() {
    let text = "O1\nG97 S800 M03\nG00 X0. Z10.\nG81 Z-20. R2. F0.1\nG80\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let hole = steps_of(&trace, text, "G81 Z-20. R2. F0.1");
    let ends: Vec<[f64; 2]> = hole.iter().map(|step| end(step)).collect();
    assert_eq!(ends, [[2.0, 0.0], [-20.0, 0.0], [2.0, 0.0]]);
    assert_eq!(hole.iter().map(|step| step.motion).collect::<Vec<_>>(), [Motion::Rapid, Motion::Feed, Motion::Rapid]);
    close(hole[1].duration, 22.0 / (0.1 * 800.0) * 60.0);
}

#[test]
fn g84_taps_at_one_lead_a_revolution_and_g87_stops_for_the_operator() {
    // The spindle is stopped: G84 switches it on. In and out at 1.5 × 500.
    let text = "O1\nG97 S500 M05\nG00 X0. Z5.\nG84 Z-15. R2. F1.5\nG80\nG87 Z-10. R2. F0.1\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let tap = steps_of(&trace, text, "G84 Z-15. R2. F1.5");
    assert_eq!(tap.len(), 3);
    for (step, z) in tap[1..].iter().zip([-15.0, 2.0]) {
        assert_eq!(step.path, Path::Thread { lead: 1.5, speed: 500.0 });
        close(step.end[1], z);
        close(step.duration, 17.0 / (1.5 * 500.0) * 60.0);
    }
    // G87 (already at R after the tap): in at feed, a program stop at the
    // bottom, out after it.
    let bore = steps_of(&trace, text, "G87 Z-10. R2. F0.1");
    let stops: Vec<Option<Stop>> = bore.iter().map(|step| step.stop).collect();
    assert_eq!(stops, [None, Some(Stop::Program), None]);
    assert_eq!(bore[1].motion, Motion::None);
    close(bore[1].end[1], -10.0);
    close(bore[2].end[1], 2.0);
    assert_eq!(trace.totals().program_stops, 1);
}

#[test]
fn g83_pecks_q_deep_back_to_r_and_in_again_above_the_material() {
    // Setting 22: in again 0.25 above the depth reached.
    let text = "O1\nG97 S800 M03\nG00 X0. Z10.\nG83 Z-14. R2. Q5. P500 F0.1\nX10.\nG80\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let hole = steps_of(&trace, text, "G83 Z-14. R2. Q5. P500 F0.1");
    let z: Vec<(Motion, f64)> = hole.iter().map(|step| (step.motion, step.end[1])).collect();
    let (dwell, feed, rapid) = (Motion::Dwell, Motion::Feed, Motion::Rapid);
    let expected = [
        (rapid, 2.0),
        (feed, -3.0),
        (rapid, 2.0),
        (rapid, -3.0 + 0.25),
        (feed, -8.0),
        (rapid, 2.0),
        (rapid, -8.0 + 0.25),
        (feed, -13.0),
        (rapid, 2.0),
        (rapid, -13.0 + 0.25),
        (feed, -14.0),
        (dwell, -14.0),
        (rapid, 2.0),
    ];
    assert_eq!(z.len(), expected.len());
    for ((motion, z), (expected_motion, expected_z)) in z.into_iter().zip(expected) {
        assert_eq!(motion, expected_motion);
        close(z, expected_z);
    }
    // Feed: the 16 mm from R, and three re-entries of 0.25.
    let fed: f64 = moves(&hole, Motion::Feed).iter().map(|step| step.length).sum();
    close(fed, 16.0 + 3.0 * 0.25);
    close(hole[11].duration, 0.5);
    // The cycle stays in force: X10. drills again there, from the R plane.
    let again = steps_of(&trace, text, "X10.");
    close_point(end(again[0]), [2.0, 5.0]);
    close_point(end(again.last().unwrap()), [2.0, 5.0]);
    assert_eq!(moves(&again, Motion::Feed).len(), 4);
}

#[test]
fn g83_degressive_pecks_shrink_by_j_down_to_k() {
    let text = "O1\nG97 S800 M03\nG00 X0. Z2.\nG83 Z-20. R2. I8. J3. K2. F0.1\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let feeds: Vec<f64> = moves(&steps_of(&trace, text, "G83 Z-20. R2. I8. J3. K2. F0.1"), Motion::Feed)
        .iter()
        .map(|step| 2.0 - step.end[1])
        .collect();
    // 8, 8−3, 8−6 → 2 (K), then 2s: 8, 13, 15, 17, 19, 21 → 22 total.
    let expected = [8.0, 13.0, 15.0, 17.0, 19.0, 21.0, 22.0];
    assert_eq!(feeds.len(), expected.len());
    for (depth, expected) in feeds.into_iter().zip(expected) {
        close(depth, expected);
    }
}

#[test]
fn g75_pecks_grooves_k_apart_and_g74_along_z() {
    // Grooves from Z-10 to Z-17, 4 apart (the last step 3), each plunged
    // from Ø40 to Ø30 in pecks of I2 (radius), Setting 22 back after each.
    let text = "O1\nG97 S500 M03\nG00 X40. Z-10.\nG75 X30. Z-17. I2. K4. F0.05\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let grooves = steps_of(&trace, text, "G75 X30. Z-17. I2. K4. F0.05");
    let bottoms: Vec<f64> = grooves.iter().filter(|step| (step.end[0] - 15.0).abs() < 1e-9).map(|s| s.end[1]).collect();
    assert_eq!(bottoms, [-10.0, -14.0, -17.0]);
    // Per groove: pecks to 18, 16, 15 (5 deep in 2s), backing 0.25.
    let fed: f64 = moves(&grooves, Motion::Feed).iter().map(|step| step.length).sum();
    close(fed, 3.0 * (5.0 + 2.0 * 0.25));
    close_point(end(grooves.last().unwrap()), [-10.0, 20.0]);
    // G74 pecks along Z: a deep hole of 12 in K5s.
    let text = "O1\nG97 S500 M03\nG00 X0. Z2.\nG74 Z-10. K5. F0.1\nM30\n";
    let trace = run(text, &lathe(&[]), 100);
    no_findings(&trace);
    let hole = steps_of(&trace, text, "G74 Z-10. K5. F0.1");
    let z: Vec<f64> = moves(&hole, Motion::Feed).iter().map(|step| step.end[1]).collect();
    assert_eq!(z, [-3.0, -8.0, -10.0]);
    close_point(end(hole.last().unwrap()), [2.0, 0.0]);
}

#[test]
fn cycles_that_cannot_run_are_refused_at_their_block_and_never_loop() {
    let refused = |text: &str, line: &str| {
        let trace = run(text, &lathe(&[]), 1000);
        let failed: Vec<&str> = trace
            .findings
            .iter()
            .filter(|finding| finding.rule == RunRule::CycleFailed)
            .map(|finding| text[finding.range].trim())
            .collect();
        assert_eq!(failed, [line], "{:?}", trace.findings);
    };
    let contour = "N10 G00 X40.\nG01 Z-30.\nN20 X62.\n";
    refused(&format!("O1\nG00 X60. Z2.\nG71 P10 Q20 U0.5 D0 F0.3\n{contour}M30\n"), "G71 P10 Q20 U0.5 D0 F0.3");
    refused(&format!("O1\nG00 X60. Z2.\nG71 P10 Q20 U0.5 D-2. F0.3\n{contour}M30\n"), "G71 P10 Q20 U0.5 D-2. F0.3");
    refused(&format!("O1\nG00 X60. Z2.\nG71 P10 Q20 U0.5 F0.3\n{contour}M30\n"), "G71 P10 Q20 U0.5 F0.3");
    refused(&format!("O1\nG00 X60. Z2.\nG71 P10 Q20 D0.0001 F0.3\n{contour}M30\n"), "G71 P10 Q20 D0.0001 F0.3");
    refused(&format!("O1\nG00 X60. Z2.\nG73 P10 Q20 D2.5 F0.3\n{contour}M30\n"), "G73 P10 Q20 D2.5 F0.3");
    refused("O1\nG97 S800 M03\nG83 Z-10. R2. Q0 F0.1\nM30\n", "G83 Z-10. R2. Q0 F0.1");
    refused("O1\nG97 S800 M03\nG83 Z-10. R2. Q2. I3. F0.1\nM30\n", "G83 Z-10. R2. Q2. I3. F0.1");
    refused("O1\nG97 S800 M03\nG83 Z-10. R2. I3. J1. F0.1\nM30\n", "G83 Z-10. R2. I3. J1. F0.1");
    refused("O1\nG97 S800 M03\nG75 X30. I-1. F0.1\nM30\n", "G75 X30. I-1. F0.1");
    refused("O1\nG97 S800 M03\nG76 Z-30. K1. D0.3 F2.\nM30\n", "G76 Z-30. K1. D0.3 F2.");
    // A contour the model cannot find stops the run too.
    let trace = run("O1\nG00 X60. Z2.\nG71 P10 Q30 D2. F0.3\nN10 X40.\nM30\n", &lathe(&[]), 1000);
    assert_eq!(trace.findings.iter().map(|finding| finding.rule).collect::<Vec<_>>(), [RunRule::CallTargetMissing]);
}

/// Runs a manual program and checks that it reaches its end with every
/// cycle run: no finding stops it, every move has its time, and only the
/// machine coordinates, work offsets and compensation are left out.
fn runs_to_its_end(text: &str, last: &str) -> Trace {
    let trace = run(text, &lathe(&[]), 100_000);
    for finding in &trace.findings {
        assert_eq!(finding.rule, RunRule::NotRunYet, "{finding:?}");
        let kind = ["G53", "G54", "G41/G42"].iter().any(|kind| finding.message.contains(kind));
        assert!(kind, "{}", finding.message);
    }
    assert_eq!(text[trace.steps.last().unwrap().range].trim(), last);
    for step in &trace.steps {
        let timed = step.length == 0.0 || step.duration > 0.0;
        assert!(timed, "{} has no time", text[step.range].trim());
    }
    trace
}

/// The cycle block's steps: its moves, in count and kind.
fn cycle_moves(trace: &Trace, text: &str, line: &str) -> (usize, usize) {
    let steps = steps_of(trace, text, line);
    (moves(&steps, Motion::Rapid).len(), moves(&steps, Motion::Feed).len())
}

#[test]
fn the_manual_s_e14_rough_and_finish_runs_to_its_end() {
    let text = include_str!("../../syntax/test_data/haas-lathe/e14_g71_type1_program.nc");
    let trace = runs_to_its_end(text, "M30");
    // D8 from Ø70 + U/2: levels at 27.15, 19.15, 11.15 (3.15 is under the
    // floor 8.65): three cuts, the pass along the contour's nine feeds.
    assert_eq!(cycle_moves(&trace, text, "G71 P10 Q20 U0.3 W0.1 D8. F0.3").1, 3 + 8);
    assert_eq!(cycle_moves(&trace, text, "G70 P10 Q20 F0.1").1, 8);
}

#[test]
fn the_manual_s_e16_inside_roughing_runs_to_its_end() {
    let text = include_str!("../test_data/haas-lathe/e16_g71_type1_inside.nc");
    let trace = runs_to_its_end(text, "M30");
    // Inside: the levels rise from Ø20 − 0.3 by D4 (radius) toward the
    // mouth's Ø60 − 0.3: 13.85, 17.85, 21.85, 25.85.
    let cuts: Vec<f64> = moves(&steps_of(&trace, text, "G71 P1 Q8 U-0.3 W0.1 D4. F0.3"), Motion::Feed)
        .iter()
        .take(4)
        .map(|step| step.end[0])
        .collect();
    assert_eq!(cuts.len(), 4);
    for (cut, level) in cuts.into_iter().zip([13.85, 17.85, 21.85, 25.85]) {
        close(cut, level);
    }
}

#[test]
fn the_manual_s_e17_type_ii_roughing_runs_to_its_end() {
    let text = include_str!("../../syntax/test_data/haas-lathe/e17_g71_type2_template.nc");
    let trace = runs_to_its_end(text, "M30");
    // Levels D3 from Ø70 + U/2 down to the floor Ø17 + U/2: nine.
    let steps = steps_of(&trace, text, "G71 P1 Q8 U0.3 W0.1 D3. F0.3");
    let levels = ((35.15 - 8.65) / 3.0f64).ceil() as usize - 1;
    assert_eq!(levels, 8);
    let starts = steps.windows(2).filter(|pair| pair[0].motion == Motion::Rapid && pair[1].motion == Motion::Feed);
    assert_eq!(starts.count(), levels + 1);
}

#[test]
fn the_manual_s_e18_g73_runs_to_its_end() {
    let text = include_str!("../test_data/haas-lathe/e18_g73_program.nc");
    let trace = runs_to_its_end(text, "M30");
    // D4: four passes of the contour's five feed moves.
    assert_eq!(cycle_moves(&trace, text, "G73 P10 Q16 U0.3 W0.1 I9. K8. D4. F0.3").1, 4 * 5);
}

#[test]
fn the_manual_s_e25_exercise_runs_to_its_end() {
    let text = include_str!("../../syntax/test_data/haas-lathe/e25_uebung.nc");
    let trace = runs_to_its_end(text, "G00 G40 G53 X-100. Z-200.");
    // D3 from Ø70 + 0.4: levels from 32.2 down to above the floor 8.2.
    let steps = steps_of(&trace, text, "G71 P10 Q20 U0.4 W0.1 D3. F0.3");
    let cuts: Vec<f64> =
        moves(&steps, Motion::Feed).iter().take_while(|step| step.end[0] > 10.0).map(|s| s.end[0]).collect();
    let expected: Vec<f64> = (1..).map(|k| 35.2 - 3.0 * f64::from(k)).take_while(|&level| level > 8.2 + 1e-9).collect();
    assert_eq!(expected.len(), 8);
    for (cut, level) in cuts.iter().zip(&expected) {
        close(*cut, *level);
    }
}

#[test]
fn the_manual_s_g90_example_cuts_from_the_start_point() {
    let text = include_str!("../test_data/haas-lathe/e19_g90_program.nc");
    let trace = runs_to_its_end(text, "M30");
    // Each pass from X52: U-12, -17, -22, -27 as the comments say.
    for (line, u) in
        [("N2 X40. (U-12)", -12.0), ("N3 X35. (U-17)", -17.0), ("N4 X30. (U-22)", -22.0), ("N5 X25. (U-27)", -27.0)]
    {
        let pass = steps_of(&trace, text, line);
        close_point(end(pass[1]), [-30.0, (52.0 + u) / 2.0]);
        close_point(end(pass[3]), [3.0, 26.0]);
    }
}

mod any_words {
    use proptest::prelude::*;

    use super::{lathe, run};
    use nc_exec::haas_lathe::cycles::MAX_MOVES;

    /// A word's value: zero, signs, tiny and odd sizes.
    fn value() -> impl Strategy<Value = String> {
        prop::sample::select(vec!["0", "-1.", "0.001", "0.5", "2.", "3.7", "-12.5", "40.", "4.", "1", "#1", "[1/3]"])
            .prop_map(str::to_owned)
    }

    /// A cycle with the word it needs most (ending each code) and others.
    fn cycle() -> impl Strategy<Value = String> {
        let codes = prop::sample::select(vec![
            "G70 P10 Q20 F",
            "G71 P10 Q20 D",
            "G72 P10 Q20 D",
            "G73 P10 Q20 D",
            "G74 Z-20. K",
            "G75 X20. I",
            "G76 X50. D",
            "G90 X",
            "G92 X",
            "G94 Z",
            "G32 Z",
            "G81 Z",
            "G83 Z-10. Q",
            "G84 Z",
            "G87 Z",
            "G184 Z",
        ]);
        let letters = prop::collection::vec((prop::sample::select(b"XZUWIKDAPQRJL".to_vec()), value()), 0..5);
        (codes, value(), letters).prop_map(|(code, needed, words)| {
            let words: Vec<String> =
                words.into_iter().map(|(letter, value)| format!("{}{value}", char::from(letter))).collect();
            format!("{code}{needed} {} F0.2", words.join(" "))
        })
    }

    fn contour() -> impl Strategy<Value = Vec<String>> {
        let block = prop::sample::select(vec![
            "G00 X20.",
            "G01 Z-10.",
            "X30. Z-15.",
            "G02 U10. W-5. R5.",
            "G03 U-10. W-5. R5.",
            "G02 W-10. R-6.",
            "Z-40.",
            "X10.",
            "U5. W-3.",
            "G03 U20. W-10. R10.",
            "G00 X62.",
        ]);
        prop::collection::vec(block, 1..6).prop_map(|blocks| blocks.into_iter().map(str::to_owned).collect())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn any_cycle_words_run_to_an_end(cycle in cycle(), contour in contour(), repeat in value()) {
            let mut text = format!("O1\n#1 = 2.\nG97 S500 M03\nG00 X60. Z2.\n{cycle}\nN10 {}\n", contour[0]);
            for block in &contour[1..] {
                text.push_str(block);
                text.push('\n');
            }
            text.push_str(&format!("N20 G00 X{repeat}\nX45.\nM30\n"));
            let trace = run(&text, &lathe(&[]), 1000);
            prop_assert!(trace.steps.len() <= 4 * MAX_MOVES);
            for step in &trace.steps {
                prop_assert!(step.duration.is_finite() && step.length.is_finite(), "{text}\n{step:?}");
            }
        }
    }
}
