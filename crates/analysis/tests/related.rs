//! Related locations point into the file that explains the finding.

use std::fs;

use ncc_analysis::{AnalysisHost, Config};

#[test]
fn a_setting_made_in_a_macrocycle_points_at_the_call() {
    let config =
        Config::from_toml("[machine]\naxes = [\"X\", \"Z\"]\nfeed-limit = 2000\n", "ncc.toml".as_ref(), |path| {
            fs::read_to_string(path)
        })
        .unwrap();
    let mut host = AnalysisHost::new(config);
    let main = "%1\nN10 G90 G95 G00 X60. Z2. M03\nN20 G72 L9001\nN30 G01 X5. F3000\nN40 M30\n*\n";
    let file = host.add_file("main.NCP", main);
    host.add_file("L9001", "N1 G79 L9001\nN2 S1000\nN3 G70\n");
    let found = host.analysis().diagnostics(file);
    let too_fast = found.iter().find(|d| d.name == "feed-per-rev-exceeds-max-velocity").expect("the S1000 of L9001");
    let related = &too_fast.related[..];
    assert_eq!(related.len(), 1, "{related:#?}");
    assert_eq!(related[0].file, None);
    assert_eq!(&main[related[0].range], "G72");
}

#[test]
fn a_subprogram_called_twice_reports_once() {
    let mut host = AnalysisHost::default();
    let text =
        "%1\nN10 R1=123\nN20 G71 L100\nN30 R1=123\nN40 G71 L100\nN50 M30\nN100 G79 L100\nN110 GR1\nN120 G70\n*\n";
    let file = host.add_file("main.NCP", text);
    let found = host.analysis().diagnostics(file);
    let overflows: Vec<_> = found.iter().filter(|d| d.name == "parameter-digit-overflow").collect();
    assert_eq!(overflows.len(), 1, "{found:#?}");
    let origin = overflows[0].related[0].range;
    assert_eq!(usize::from(origin.start()), text.find("123").unwrap(), "the value before the first call");
}
