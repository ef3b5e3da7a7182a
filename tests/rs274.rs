//! Differential tests of the executor against LinuxCNC's `rs274`
//! interpreter: seeded random programs in the motion subset a dialect
//! shares with NGC, run by ncc and by `rs274 -g`. Every motion must end at
//! the same point, with the same kind, feed and path length.
//!
//! - CNC8x6: G00–G03 with I/J in the XY plane, helices, G90/G91, F, run by
//!   `ncc run --format json`.
//! - The Haas lathe: G00–G03 in the ZX plane with X as a diameter, U/W
//!   increments mixed with X/Z, arcs by I/K (I a radius) or by R, against
//!   rs274 in lathe diameter mode (`G18 G7`). The dialect is not on the
//!   command line yet, so its interpreter is run directly.
//!
//! Ignored by default because it needs `rs274` (Debian's linuxcnc-uspace);
//! `.ci/run` installs it and runs this test.

use std::{
    f64::consts::TAU,
    fmt::Write,
    fs,
    path::Path,
    process::{Command, Stdio},
    sync::Mutex,
};

use nc_exec::{
    machine::MachineConfig,
    run::{self, Motion, NoFiles, Path as StepPath},
};
use ncc_bench::{edits::Lcg, rs274};
use ncc_catalog::Dialect;
use serde_json::{Value, json};

const PROGRAMS: u64 = 40;
const MOTIONS_PER_PROGRAM: usize = 250;

/// Both sides read the same coordinates, exact on the 1 µm grid, and rs274
/// prints four decimals (off by at most 0.05 µm); floating-point sums of
/// G91 increments drift far less. A difference above the control's 1 µm
/// arc tolerance is therefore a real one.
const TOLERANCE_MM: f64 = 1e-3;

/// One motion block in ncc's dialect and in NGC, and where the generator
/// meant it to end, in µm.
struct Block {
    cnc: String,
    ngc: String,
    end: [i64; 3],
}

/// A motion as one side ran it.
#[derive(Debug)]
struct Ran {
    rapid: bool,
    /// X, Y, Z in mm.
    end: [f64; 3],
    /// mm/min; `None` for rapids.
    feed: Option<f64>,
    length: f64,
}

impl Ran {
    fn agrees_with(&self, other: &Ran) -> bool {
        let close = |a: f64, b: f64| (a - b).abs() <= TOLERANCE_MM;
        // Feeds the interpreter derives (a thread's lead times the speed)
        // may differ in the last bit.
        let same_feed = match (self.feed, other.feed) {
            (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * a.abs().max(b.abs()),
            (a, b) => a == b,
        };
        self.rapid == other.rapid
            && same_feed
            && close(self.length, other.length)
            && (0..3).all(|axis| close(self.end[axis], other.end[axis]))
    }
}

#[test]
#[ignore = "needs LinuxCNC's rs274; .ci/run installs it"]
fn motion_matches_rs274() {
    differential("CNC8x6", |rs274, dir, seed| {
        let (cnc, ngc, blocks) = generate(seed);
        let (cnc_file, ngc_file) = (dir.join(format!("{seed}.NCP")), dir.join(format!("{seed}.ngc")));
        fs::write(&cnc_file, cnc).unwrap();
        fs::write(&ngc_file, ngc).unwrap();
        (blocks, ncc_motions(&cnc_file), rs274_motions(rs274, &ngc_file))
    });
}

/// Runs `PROGRAMS` random programs, each made and run by ncc and rs274 in
/// `run_both` (its blocks, ncc's motions, rs274's), compares them, and
/// prints the largest end-point difference.
fn differential(dialect: &str, mut run_both: impl FnMut(&Path, &Path, u64) -> (Vec<Block>, Vec<Ran>, Vec<Ran>)) {
    let rs274 = rs274::find().expect(rs274::MISSING);
    let dir = tempfile::tempdir().unwrap();
    let mut largest_difference: f64 = 0.0;
    for seed in 1..=PROGRAMS {
        let (blocks, ncc, peer) = run_both(&rs274, dir.path(), seed);
        largest_difference = largest_difference.max(compare(seed, dialect, &blocks, &ncc, &peer));
    }
    eprintln!(
        "{PROGRAMS} {dialect} programs, {} motions: largest end-point difference {:.4} µm",
        PROGRAMS as usize * MOTIONS_PER_PROGRAM,
        largest_difference * 1000.0
    );
}

/// Checks that ncc and rs274 ran every block alike and where it was meant
/// to end; the largest difference of an end point (mm).
fn compare(seed: u64, dialect: &str, blocks: &[Block], ncc: &[Ran], peer: &[Ran]) -> f64 {
    assert_eq!((ncc.len(), peer.len()), (blocks.len(), blocks.len()), "motions of seed {seed}: (ncc, rs274)");
    let mut largest_difference: f64 = 0.0;
    for (index, ((block, ncc), peer)) in blocks.iter().zip(ncc).zip(peer).enumerate() {
        let intended = block.end.map(|um| um as f64 / 1000.0);
        let intended_reached = (0..3).all(|axis| (ncc.end[axis] - intended[axis]).abs() <= TOLERANCE_MM);
        assert!(
            ncc.agrees_with(peer) && intended_reached,
            "seed {seed}, motion {}:\n  {dialect:<9} {}\n  NGC       {}\n  intended  {intended:?}\n  ncc       \
             {ncc:?}\n  rs274     {peer:?}",
            index + 1,
            block.cnc,
            block.ngc,
        );
        for axis in 0..3 {
            largest_difference = largest_difference.max((ncc.end[axis] - peer.end[axis]).abs());
        }
    }
    largest_difference
}

/// A program of random motion blocks as CNC8x6 and NGC text, and its
/// blocks. Points are whole µm, which three decimals write exactly, so both
/// texts mean the same numbers and G91 increments add up without rounding.
fn generate(seed: u64) -> (String, String, Vec<Block>) {
    let mut rng = Lcg::new(seed);
    let mut cnc = String::from("%1\n");
    let mut ngc = String::from("G21 G17 G90 G94\n");
    let mut blocks = Vec::with_capacity(MOTIONS_PER_PROGRAM);
    let mut at = [0; 3];
    let (mut incremental, mut modal, mut feed_set) = (false, None, false);
    for n in 1..=MOTIONS_PER_PROGRAM {
        let mut words = Vec::new();
        if rng.below(8) == 0 {
            incremental = !incremental;
            words.push(if incremental { "G91" } else { "G90" }.to_owned());
        }
        let code = [0, 0, 1, 1, 1, 1, 2, 2, 3, 3][rng.below(10)];
        // Motion is modal: the G code may be left out when it repeats.
        if modal != Some(code) || rng.below(3) > 0 {
            words.push(format!("G0{code}"));
        }
        modal = Some(code);
        let mut end = at;
        let (written, centre_offset) = if code < 2 {
            // A non-empty subset of X, Y, Z.
            let axes = 1 + rng.below(7);
            let written = [0, 1, 2].map(|axis| axes >> axis & 1 == 1);
            for axis in (0..3).filter(|&axis| written[axis]) {
                end[axis] = coordinate(&mut rng, axis);
            }
            (written, None)
        } else {
            let (xy, offset) = arc(&mut rng, at, code == 2);
            end[..2].copy_from_slice(&xy);
            // The plane comes from the axes written, so X and Y always are;
            // with Z the arc becomes a helix.
            let helix = rng.below(5) == 0;
            if helix {
                end[2] = coordinate(&mut rng, 2);
            }
            ([true, true, helix], Some(offset))
        };
        for axis in (0..3).filter(|&axis| written[axis]) {
            let value = if incremental { end[axis] - at[axis] } else { end[axis] };
            words.push(format!("{}{}", ['X', 'Y', 'Z'][axis], mm(value)));
        }
        if let Some([i, j]) = centre_offset {
            words.push(format!("I{} J{}", mm(i), mm(j)));
        }
        // Whole mm/min: with a decimal point CNC8x6 reads F in m/min.
        if code > 0 && (!feed_set || rng.below(5) == 0) {
            words.push(format!("F{}", 1 + rng.below(20_000)));
            feed_set = true;
        }
        let words = words.join(" ");
        let block = Block { cnc: format!("N{n} {words}"), ngc: words, end };
        writeln!(cnc, "{}", block.cnc).unwrap();
        writeln!(ngc, "{}", block.ngc).unwrap();
        blocks.push(block);
        at = end;
    }
    writeln!(cnc, "N{} M30\n*", MOTIONS_PER_PROGRAM + 1).unwrap();
    ngc.push_str("M2\n");
    (cnc, ngc, blocks)
}

/// A random X or Y within ±150 mm, Z within ±30 mm, in µm.
fn coordinate(rng: &mut Lcg, axis: usize) -> i64 {
    let half_range = if axis == 2 { 30_000 } else { 150_000 };
    rng.below(2 * half_range + 1) as i64 - half_range as i64
}

/// An arc in the XY plane from `start`: its end point and its centre
/// relative to the start (I, J), in µm. A full circle one time in eight
/// (under G90 its end is the start written absolutely, after G91 sums),
/// else a sweep of 2° to 358°, so that over 180° is common.
fn arc(rng: &mut Lcg, start: [i64; 3], clockwise: bool) -> ([i64; 2], [i64; 2]) {
    let radius = 2_000.0 + rng.below(78_000) as f64;
    let from_centre = (rng.below(360_000) as f64 / 1000.0).to_radians();
    let offset = [(-radius * from_centre.cos()).round() as i64, (-radius * from_centre.sin()).round() as i64];
    if rng.below(8) == 0 {
        return ([start[0], start[1]], offset);
    }
    // The centre is on the grid; the end point rounded onto it moves off
    // the circle by at most √½ µm, inside the control's 1 µm.
    let centre = [start[0] + offset[0], start[1] + offset[1]];
    let radius = (offset[0] as f64).hypot(offset[1] as f64);
    let sweep = (2.0 + rng.below(356_000) as f64 / 1000.0).to_radians();
    let to_end = (-offset[1] as f64).atan2(-offset[0] as f64) + if clockwise { -sweep } else { sweep };
    let end = [centre[0] + (radius * to_end.cos()).round() as i64, centre[1] + (radius * to_end.sin()).round() as i64];
    let off_circle = ((end[0] - centre[0]) as f64).hypot((end[1] - centre[1]) as f64) - radius;
    assert!(off_circle.abs() < 1.0, "the arc's end is {off_circle} µm off its circle");
    (end, offset)
}

/// µm as mm with three decimals.
fn mm(um: i64) -> String {
    let sign = if um < 0 { "-" } else { "" };
    format!("{sign}{}.{:03}", um.abs() / 1000, um.abs() % 1000)
}

/// The motions of `ncc run --format json`.
fn ncc_motions(file: &Path) -> Vec<Ran> {
    let output = Command::new(env!("CARGO_BIN_EXE_ncc")).args(["run", "--format", "json"]).arg(file).output().unwrap();
    assert!(output.status.success(), "ncc run {} failed:\n{}", file.display(), String::from_utf8_lossy(&output.stderr));
    let run: Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(run["findings"], json!([]), "ncc run {}", file.display());
    let blocks = run["blocks"].as_array().unwrap();
    blocks
        .iter()
        .filter(|block| block["motion"] == "rapid" || block["motion"] == "feed")
        .map(|block| Ran {
            rapid: block["motion"] == "rapid",
            end: ["X", "Y", "Z"].map(|axis| block["end"]["program"][axis].as_f64().unwrap()),
            feed: block["feed_mm_min"].as_f64(),
            length: block["length_mm"].as_f64().unwrap(),
        })
        .collect()
}

/// A canonical call of `rs274 -g` that moves or sets the feed.
enum Call {
    Feed(f64),
    /// `SET_SPINDLE_SPEED`'s rpm.
    Speed(f64),
    /// `START_SPEED_FEED_SYNC`'s lead in mm per revolution, or its end.
    Sync(Option<f64>),
    /// `STRAIGHT_TRAVERSE` or `STRAIGHT_FEED` to (x, y, z).
    Straight {
        rapid: bool,
        end: [f64; 3],
    },
    /// `ARC_FEED`'s numbers: the plane's first and second coordinates of the
    /// end, of the centre, the rotation and the third axis.
    Arc(Vec<f64>),
}

/// The calls of `rs274 -g` (in mm after G21).
fn rs274_calls(rs274: &Path, file: &Path) -> Vec<Call> {
    // Two rs274 at once now and then die of a bus error (it shares memory
    // between its runs), and the tests run in parallel: one at a time.
    static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());
    let output = {
        let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        // Without -g it would wait for a key after an error.
        Command::new(rs274).arg("-g").arg(file).stdin(Stdio::null()).output().unwrap()
    };
    assert!(
        output.status.success(),
        "rs274 -g {} failed:\n{}",
        file.display(),
        String::from_utf8_lossy(&output.stderr)
    );
    let mut calls = Vec::new();
    for line in String::from_utf8(output.stdout).unwrap().lines() {
        // `   14 N..... STRAIGHT_FEED(10.5000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)`
        let Some(call) = line.trim_start().splitn(3, ' ').nth(2) else { continue };
        let Some((name, args)) = call.strip_suffix(')').and_then(|call| call.split_once('(')) else { continue };
        let numbers = || -> Vec<f64> { args.split(", ").map(|arg| arg.parse().unwrap()).collect() };
        calls.push(match name {
            "SET_FEED_RATE" => Call::Feed(numbers()[0]),
            "SET_SPINDLE_SPEED" => Call::Speed(numbers()[1]),
            // `START_SPEED_FEED_SYNC(1.500000,0)`: no blank after the comma.
            "START_SPEED_FEED_SYNC" => Call::Sync(args.split(',').next().and_then(|lead| lead.parse().ok())),
            "STOP_SPEED_FEED_SYNCH" => Call::Sync(None),
            "STRAIGHT_TRAVERSE" | "STRAIGHT_FEED" => Call::Straight {
                rapid: name == "STRAIGHT_TRAVERSE",
                end: <[f64; 3]>::try_from(&numbers()[..3]).unwrap(),
            },
            "ARC_FEED" => Call::Arc(numbers()),
            _ => continue,
        });
    }
    calls
}

/// The motions of `rs274 -g`: `SET_FEED_RATE(f)`,
/// `STRAIGHT_TRAVERSE(x, y, z, a, b, c)`, `STRAIGHT_FEED(…)` likewise, and
/// `ARC_FEED(first, second, centre first, centre second, rotation, third,
/// a, b, c)` in the plane whose (first, second, third) axes `plane` gives
/// as indexes of (x, y, z): XY is [0, 1, 2], XZ (rs274 writes Z first) is
/// [2, 0, 1].
fn rs274_motions_in(rs274: &Path, file: &Path, plane: [usize; 3]) -> Vec<Ran> {
    let (mut at, mut feed, mut motions) = ([0.0; 3], 0.0, Vec::new());
    let (mut speed, mut lead) = (0.0, None);
    for call in rs274_calls(rs274, file) {
        let ran = match call {
            Call::Feed(rate) => {
                feed = rate;
                continue;
            }
            Call::Speed(rpm) => {
                speed = rpm;
                continue;
            }
            Call::Sync(synchronised) => {
                lead = synchronised;
                continue;
            }
            Call::Straight { rapid, end } => {
                let length = (0..3).map(|axis| (end[axis] - at[axis]).powi(2)).sum::<f64>().sqrt();
                // A thread feeds at its lead per spindle revolution.
                let rate = lead.map_or(feed, |lead| lead * speed);
                Ran { rapid, end, feed: (!rapid).then_some(rate), length }
            }
            Call::Arc(n) => {
                let mut end = [0.0; 3];
                (end[plane[0]], end[plane[1]], end[plane[2]]) = (n[0], n[1], n[5]);
                let in_plane = |point: [f64; 3]| plane.map(|axis| point[axis]);
                let length = arc_length(in_plane(at), in_plane(end), [n[2], n[3]], n[4] as i32);
                Ran { rapid: false, end, feed: Some(feed), length }
            }
        };
        at = ran.end;
        motions.push(ran);
    }
    motions
}

fn rs274_motions(rs274: &Path, file: &Path) -> Vec<Ran> {
    rs274_motions_in(rs274, file, [0, 1, 2])
}

/// In lathe diameter mode rs274 gives X as a radius, like the Haas trace.
fn rs274_lathe_motions(rs274: &Path, file: &Path) -> Vec<Ran> {
    rs274_motions_in(rs274, file, [2, 0, 1])
}

/// The length of an ARC_FEED in its plane, whose coordinates the points
/// give first and second and the helix axis third: `rotation` turns
/// counter-clockwise when positive, clockwise when negative, the last one
/// ending at the end point (a full turn when it is the start); Z rises
/// evenly along it.
fn arc_length(start: [f64; 3], end: [f64; 3], centre: [f64; 2], rotation: i32) -> f64 {
    let angle = |point: [f64; 3]| (point[1] - centre[1]).atan2(point[0] - centre[0]);
    let mut sweep = angle(end) - angle(start);
    if rotation > 0 && sweep <= 0.0 {
        sweep += TAU;
    } else if rotation < 0 && sweep >= 0.0 {
        sweep -= TAU;
    }
    let turns = sweep.abs() + f64::from(rotation.abs() - 1) * TAU;
    let radius = (start[0] - centre[0]).hypot(start[1] - centre[1]);
    (radius * turns).hypot(end[2] - start[2])
}

#[test]
#[ignore = "needs LinuxCNC's rs274; .ci/run installs it"]
fn lathe_motion_matches_rs274() {
    let machine = MachineConfig::of_control(Dialect::HaasLathe);
    differential("Haas", |rs274, dir, seed| {
        let (haas, ngc, blocks) = generate_lathe(seed);
        let ngc_file = dir.join(format!("{seed}.ngc"));
        fs::write(&ngc_file, ngc).unwrap();
        let trace = run::run(&haas, &NoFiles, &machine, 10 * MOTIONS_PER_PROGRAM);
        assert!(trace.findings.is_empty(), "seed {seed}: {:?}", trace.findings);
        (blocks, lathe_motions(&trace), rs274_lathe_motions(rs274, &ngc_file))
    });
}

/// A random lathe program as Haas and NGC text, and its blocks, whose ends
/// are kept as (radius, 0, Z) in µm like the motions compared. NGC writes
/// every end absolutely; Haas writes each axis as X/Z or as an increment
/// U/W at random, both in the same block; a tenth of the moves are
/// threads (Haas G32 F, rs274 G33 K).
fn generate_lathe(seed: u64) -> (String, String, Vec<Block>) {
    let mut rng = Lcg::new(seed);
    // Threads run at the lead per revolution of this spindle speed.
    let mut haas = String::from("O1\nG98\nG97 S500 M03\n");
    let mut ngc = String::from("G21 G18 G7 G90 G94\nS500 M3\n");
    let mut blocks = Vec::with_capacity(MOTIONS_PER_PROGRAM);
    // (radius, Z) in µm.
    let mut at = [0i64; 2];
    let (mut modal, mut feed_set) = (None, false);
    let diameter = |radius: i64| mm(2 * radius);
    for _ in 0..MOTIONS_PER_PROGRAM {
        if rng.below(10) == 0 {
            // A thread G32 (rs274's G33): along Z, tapered at times, at a
            // lead of 0.5 to 3 mm.
            let mut end = [at[0], at[1] - 1_000 - rng.below(20_000) as i64];
            if end[1] < -150_000 {
                end[1] = at[1] + 1_000 + rng.below(5_000) as i64;
            }
            if rng.below(2) == 0 {
                end[0] = (at[0] + rng.below(4_001) as i64 - 2_000).max(1_000);
            }
            let lead = mm(500 + rng.below(2_500) as i64);
            let (x, z) = (diameter(end[0]), mm(end[1]));
            let block = Block {
                cnc: format!("G32 X{x} Z{z} F{lead}"),
                ngc: format!("G33 X{x} Z{z} K{lead}"),
                end: [end[0], 0, end[1]],
            };
            writeln!(haas, "{}", block.cnc).unwrap();
            writeln!(ngc, "{}", block.ngc).unwrap();
            blocks.push(block);
            at = end;
            // F was the lead: the next feed move writes its own.
            (modal, feed_set) = (Some(32), false);
            continue;
        }
        let code = [0, 0, 1, 1, 1, 1, 2, 2, 3, 3][rng.below(10)];
        let mut haas_words = Vec::new();
        if modal != Some(code) || rng.below(3) > 0 {
            haas_words.push(format!("G0{code}"));
        }
        modal = Some(code);
        let mut ngc_words = vec![format!("G{code}")];
        let mut end = at;
        let mut written = [true, true];
        let mut centre = None;
        if code < 2 {
            let axes = 1 + rng.below(3);
            written = [axes & 1 == 1, axes & 2 == 2];
            if written[0] {
                end[0] = 1_000 + rng.below(149_000) as i64;
            }
            if written[1] {
                end[1] = rng.below(160_001) as i64 - 150_000;
            }
        } else {
            let (to, offset) = lathe_arc(&mut rng, at, code == 2);
            end = to;
            centre = Some(offset);
        }
        let axis_words = |haas_words: &mut Vec<String>, ngc_words: &mut Vec<String>, rng: &mut Lcg| {
            if written[0] {
                let word = if rng.below(3) == 0 {
                    format!("U{}", diameter(end[0] - at[0]))
                } else {
                    format!("X{}", diameter(end[0]))
                };
                haas_words.push(word);
                ngc_words.push(format!("X{}", diameter(end[0])));
            }
            if written[1] {
                let word =
                    if rng.below(3) == 0 { format!("W{}", mm(end[1] - at[1])) } else { format!("Z{}", mm(end[1])) };
                haas_words.push(word);
                ngc_words.push(format!("Z{}", mm(end[1])));
            }
        };
        axis_words(&mut haas_words, &mut ngc_words, &mut rng);
        if let Some((offset, sweep_over_half)) = centre {
            // The centre as I/K, or the radius, negative beyond a half turn.
            if rng.below(2) == 0 {
                let words = format!("I{} K{}", mm(offset[0]), mm(offset[1]));
                haas_words.push(words.clone());
                ngc_words.push(words);
            } else {
                let radius = (offset[0] as f64).hypot(offset[1] as f64).round() as i64;
                let signed = if sweep_over_half { -radius } else { radius };
                haas_words.push(format!("R{}", mm(signed)));
                ngc_words.push(format!("R{}", mm(signed)));
            }
        }
        if code > 0 && (!feed_set || rng.below(5) == 0) {
            let feed = format!("F{}", 1 + rng.below(5_000));
            haas_words.push(feed.clone());
            ngc_words.push(feed);
            feed_set = true;
        }
        let block = Block { cnc: haas_words.join(" "), ngc: ngc_words.join(" "), end: [end[0], 0, end[1]] };
        writeln!(haas, "{}", block.cnc).unwrap();
        writeln!(ngc, "{}", block.ngc).unwrap();
        blocks.push(block);
        at = end;
    }
    haas.push_str("M30\n");
    ngc.push_str("M2\n");
    (haas, ngc, blocks)
}

/// An arc in the ZX plane from `start` (radius, Z in µm): its end, its
/// centre relative to the start (I as a radius, K), and whether it turns
/// more than half a circle. Sweeps of 2° to 178° or 182° to 358°: an arc
/// by R near a half turn is ill-conditioned on either side. The centre is
/// on the grid and the end rounded onto it, within √½ µm of the circle.
fn lathe_arc(rng: &mut Lcg, start: [i64; 2], clockwise: bool) -> ([i64; 2], ([i64; 2], bool)) {
    let radius = 2_000.0 + rng.below(60_000) as f64;
    let from_centre = (rng.below(360_000) as f64 / 1000.0).to_radians();
    let offset = [(-radius * from_centre.cos()).round() as i64, (-radius * from_centre.sin()).round() as i64];
    let centre = [start[0] + offset[0], start[1] + offset[1]];
    let radius = (offset[0] as f64).hypot(offset[1] as f64);
    let degrees = 2.0 + rng.below(352_000) as f64 / 1000.0;
    let degrees = if degrees >= 178.0 { degrees + 4.0 } else { degrees };
    let sweep = degrees.to_radians();
    // In (Z, X) seen with Z to the right and X up, clockwise turns negative.
    let angle = |x: f64, z: f64| x.atan2(z);
    let to_end = angle(-offset[0] as f64, -offset[1] as f64) + if clockwise { -sweep } else { sweep };
    let end = [centre[0] + (radius * to_end.sin()).round() as i64, centre[1] + (radius * to_end.cos()).round() as i64];
    (end, (offset, degrees > 180.0))
}

/// The motions of the Haas interpreter's trace, with X as the radius it
/// keeps and Y zero.
fn lathe_motions(trace: &run::Trace) -> Vec<Ran> {
    let slot = |letter: u8| trace.axes.iter().position(|&axis| axis == letter).unwrap();
    let (x, z) = (slot(b'X'), slot(b'Z'));
    trace
        .steps
        .iter()
        .filter(|step| matches!(step.motion, Motion::Rapid | Motion::Feed))
        .map(|step| {
            assert!(
                matches!(step.path, StepPath::Straight | StepPath::Arc { .. } | StepPath::Thread { .. }),
                "{:?}",
                step.path
            );
            Ran {
                rapid: step.motion == Motion::Rapid,
                end: [step.end[x], 0.0, step.end[z]],
                feed: step.feed,
                length: step.length,
            }
        })
        .collect()
}
