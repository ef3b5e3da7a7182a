//! End-to-end test of the Neovim client in `editors/nvim`: a headless Neovim
//! with the plugin on its runtimepath talks to the real `ncc lsp`.
//!
//! Without `nvim` on the PATH the test passes with a note, unless
//! `NCC_REQUIRE_NVIM=1` (as in CI).

use std::{
    fs,
    path::{Path, PathBuf},
    process::{Command, Stdio},
    thread,
    time::{Duration, Instant},
};

use serde_json::{Value, json};

/// Neovim is killed after this long; its own waits are shorter.
const DEADLINE: Duration = Duration::from_secs(10);
const LUA_TIMEOUT_MS: u64 = 3000;

/// One error: the space after the sign of `X-`.
const PROGRAM: &str = "%1\nN10 G01 X- 5 F100\nN20 M30\n*\n";
const MACRO: &str = "N10 G79 L9001\nN20 G90 G00 Z2.\nN30 G70\n*\n";
/// A Sinumerik program with one error: the `(` not closed on line 4.
const SINUMERIK: &str = "%_N_MAIN_MPF\n; a part\nDEF REAL DEPTH=2.5\nR1=(5+2\n/1 N10 G642 SOFT X=R1 CR=2 F100 M3 S1000\n\
    START: $P_UIFR[1,X,TR]=5\nIF DEPTH>2 GOTOB START\nMSG(\"DONE \"<<DEPTH)\nCYCLE81(10,0,2) M30\n";
/// Where the syntax file highlights what in `SINUMERIK`.
const SINUMERIK_HIGHLIGHT: [(usize, &str, &str); 20] = [
    (0, "%_N_MAIN_MPF", "sinumerikHeader"),
    (1, "; a part", "sinumerikComment"),
    (2, "DEF", "sinumerikDeclaration"),
    (2, "REAL", "sinumerikType"),
    (2, "2.5", "sinumerikNumber"),
    (3, "R1", "sinumerikParameter"),
    (4, "/1", "sinumerikBlockSkip"),
    (4, "N10", "sinumerikBlockNumber"),
    (4, "G642", "sinumerikGCode"),
    (4, "SOFT", "sinumerikWordCode"),
    (4, "X=", "sinumerikAxis"),
    (4, "CR", "sinumerikAddress"),
    (5, "START", "sinumerikLabel"),
    (5, "$P_UIFR", "sinumerikSystemVariable"),
    (6, "IF", "sinumerikStatement"),
    (6, "GOTOB", "sinumerikStatement"),
    (7, "MSG", "sinumerikFunction"),
    (7, "\"DONE", "sinumerikString"),
    (8, "CYCLE81", "sinumerikCycle"),
    (8, "M30", "sinumerikFlow"),
];
/// A Haas lathe program, in a file named by its program number.
const HAAS: &str = "%\nO01234 (SHAFT)\nN10 G28 U0 W0 (HOME)\n/1 N20 T0101 S1200 M03\n\
    N30 #100 = #[#1+2] * SIN[30.]\nN40 IF [#100 GT 0] GOTO50\nN50 WHILE [#1 LE 3] DO1\n\
    N60 G01 X-20. ,C1. F.1\nN70 END1\nN80 M30\n%\n";
/// Where the syntax file highlights what in `HAAS`: the line, the text and
/// the group at its first character.
const HAAS_HIGHLIGHT: [(usize, &str, &str); 22] = [
    (0, "%", "haasLatheTapeMark"),
    (1, "O01234", "haasLatheProgramNumber"),
    (1, "SHAFT", "haasLatheProgramName"),
    (2, "N10", "haasLatheBlockNumber"),
    (2, "G28", "haasLatheGCode"),
    (2, "U0", "haasLatheAxis"),
    (2, "(HOME)", "haasLatheComment"),
    (3, "/1", "haasLatheBlockSkip"),
    (3, "T0101", "haasLatheAddress"),
    (3, "0101", "haasLatheNumber"),
    (3, "M03", "haasLatheMCode"),
    (4, "#100", "haasLatheVariable"),
    (4, "[", "haasLatheBracket"),
    (4, "SIN", "haasLatheFunction"),
    (5, "IF", "haasLatheConditional"),
    (5, "GT", "haasLatheOperatorWord"),
    (5, "GOTO", "haasLatheGoto"),
    (6, "WHILE", "haasLatheRepeat"),
    (6, "DO1", "haasLatheRepeat"),
    (7, "-20.", "haasLatheNumber"),
    (7, ",C", "haasLatheCorner"),
    (9, "M30", "haasLatheFlow"),
];

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// The first line of `nvim --version`, or `None` when there is no `nvim`.
fn nvim_version() -> Option<String> {
    let output = Command::new("nvim").arg("--version").output().ok()?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    output.status.success().then(|| stdout.lines().next().unwrap_or_default().to_owned())
}

/// `nvim --headless` with the driver script; killed at the deadline.
fn run_nvim(input: &Path, state: &Path) {
    let log = |name: &str| fs::File::create(state.join(name)).unwrap();
    let mut child = Command::new("nvim")
        .args(["--headless", "--clean", "-u"])
        .arg(workspace().join("tests/fixtures/nvim/init.lua"))
        .env("NCC_NVIM_TEST", input)
        // Neovim's logs (and the LSP log) go to the temporary directory.
        .env("XDG_STATE_HOME", state)
        .env("XDG_CACHE_HOME", state)
        .stdin(Stdio::null())
        .stdout(log("stdout"))
        .stderr(log("stderr"))
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > DEADLINE {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("Neovim did not finish within {DEADLINE:?}\n{}", nvim_logs(state));
        }
        thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "Neovim exited with {status}\n{}", nvim_logs(state));
}

/// What Neovim and the server said, for failure messages.
fn nvim_logs(state: &Path) -> String {
    ["stdout", "stderr", "nvim/lsp.log"]
        .iter()
        .map(|name| format!("--- {name}:\n{}", fs::read_to_string(state.join(name)).unwrap_or_default()))
        .collect()
}

#[test]
fn neovim_detects_programs_and_shows_diagnostics_hover_and_the_cycle_time() {
    let Some(version) = nvim_version() else {
        if std::env::var("NCC_REQUIRE_NVIM").as_deref() == Ok("1") {
            panic!("nvim is not on the PATH, and NCC_REQUIRE_NVIM=1 requires it");
        }
        eprintln!("nvim is not on the PATH: the Neovim test did not run (NCC_REQUIRE_NVIM=1 makes this a failure)");
        return;
    };
    eprintln!("testing with {version}");

    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path().canonicalize().unwrap();
    let project = dir.join("project");
    let programs = project.join("programs");
    fs::create_dir_all(&programs).unwrap();
    fs::write(project.join("ncc.toml"), "# The project root.\n").unwrap();
    fs::write(programs.join("drill.NCP"), PROGRAM).unwrap();
    fs::write(programs.join("L9001"), MACRO).unwrap();
    fs::write(programs.join("MAIN.MPF"), SINUMERIK).unwrap();
    fs::write(programs.join("O01234"), HAAS).unwrap();
    // Passed as `configFile`: the server reports S003 as a warning only if it
    // got the file.
    let config = dir.join("machine.toml");
    fs::write(&config, "[rules]\nS003 = \"warning\"\n").unwrap();

    // The second line holds both the error and the G code to hover.
    let line = PROGRAM.lines().nth(1).unwrap();
    let state = dir.join("state");
    fs::create_dir(&state).unwrap();
    let output_path = dir.join("output.json");
    let probes = [
        "part.Ncp",
        "L12.txt",
        "Lathe",
        "O1234.nc",
        "PART.TAP",
        "sub.spf",
        "O1234.nc.bak",
        "MPF",
        "O1",
        "O1234.txt",
        "Oa1",
        "OLD",
    ]
    .map(|name| programs.join(name));
    let probes_of = |text: &str, highlight: &[(usize, &str, &str)]| -> Vec<Value> {
        let lines: Vec<&str> = text.lines().collect();
        highlight
            .iter()
            .map(|&(line, text, _)| json!({ "line": line, "character": lines[line].find(text).unwrap() }))
            .collect()
    };
    let input = json!({
        "runtime": workspace().join("editors/nvim"),
        "server": env!("CARGO_BIN_EXE_ncc"),
        "config_file": config,
        "macro": programs.join("L9001"),
        "program": programs.join("drill.NCP"),
        "sinumerik": programs.join("MAIN.MPF"),
        "sinumerik_probes": probes_of(SINUMERIK, &SINUMERIK_HIGHLIGHT),
        "haas": programs.join("O01234"),
        "haas_probes": probes_of(HAAS, &HAAS_HIGHLIGHT),
        "hover": { "line": 1, "character": line.find("G01").unwrap() },
        "timeout_ms": LUA_TIMEOUT_MS,
        "filetype_probes": probes,
        "output": output_path,
    });
    let input_path = dir.join("input.json");
    fs::write(&input_path, input.to_string()).unwrap();

    run_nvim(&input_path, &state);
    let output = fs::read_to_string(&output_path)
        .unwrap_or_else(|error| panic!("the driver wrote no output: {error}\n{}", nvim_logs(&state)));
    let output: Value = serde_json::from_str(&output).unwrap();
    let context = format!("{output:#}\n{}", nvim_logs(&state));
    assert_eq!(output.get("error"), None, "{context}");

    let filetypes = &output["filetypes"];
    let detected = [
        ("drill.NCP", "cnc8x6"),
        ("L9001", "cnc8x6"),
        ("part.Ncp", "cnc8x6"),
        ("MAIN.MPF", "sinumerik"),
        ("sub.spf", "sinumerik"),
        ("O1234.nc", "haas-lathe"),
        ("PART.TAP", "haas-lathe"),
        ("O01234", "haas-lathe"),
        ("O1", "haas-lathe"),
    ];
    for (name, filetype) in detected {
        assert_eq!(filetypes[name], filetype, "{name}: {context}");
    }
    for name in ["L12.txt", "Lathe", "O1234.nc.bak", "MPF", "O1234.txt", "Oa1", "OLD"] {
        let filetype = filetypes[name].as_str().unwrap_or_default();
        assert!(!["cnc8x6", "haas-lathe", "sinumerik"].contains(&filetype), "{name}: {context}");
    }
    assert_eq!(output["highlight"], "cnc8x6GCode", "{context}");
    let groups: Vec<&str> = HAAS_HIGHLIGHT.iter().map(|&(_, _, group)| group).collect();
    assert_eq!(output["haas_highlight"], json!(groups), "{context}");
    assert_eq!(output["haas_commentstring"], "(%s)", "{context}");
    let groups: Vec<&str> = SINUMERIK_HIGHLIGHT.iter().map(|&(_, _, group)| group).collect();
    assert_eq!(output["sinumerik_highlight"], json!(groups), "{context}");
    assert_eq!(output["sinumerik_commentstring"], ";%s", "{context}");

    // One server for the project, found by its `ncc.toml`, serves all four
    // files.
    let clients = output["clients"].as_array().unwrap();
    assert_eq!(clients.len(), 1, "{context}");
    assert_eq!(clients[0]["name"], "ncc", "{context}");
    assert_eq!(clients[0]["root_dir"], json!(project), "{context}");
    let init_options = json!({ "configFile": config, "cycleTime": { "inlayHints": "perBlock" } });
    assert_eq!(clients[0]["init_options"], init_options, "{context}");
    assert_eq!(
        clients[0]["buffers"],
        json!({ "program": true, "macro": true, "sinumerik": true, "haas": true }),
        "{context}"
    );

    let space_after_sign = json!({
        "code": "S003",
        "source": "ncc",
        "severity": "WARN",
        "line": 1,
        "character": line.find("- ").unwrap(),
    });
    assert_eq!(output["diagnostics"], json!([space_after_sign]), "{context}");

    // The Sinumerik program's syntax error.
    let unclosed = json!({ "code": "S029", "source": "ncc", "severity": "ERROR", "line": 3, "character": 3 });
    assert_eq!(output["sinumerik_diagnostics"], json!([unclosed]), "{context}");

    // The predicted total on the header: 5 mm at 100 mm/min, with its
    // ramps and the stop at the end.
    assert_eq!(
        output["code_lenses"],
        json!(["Cycle time 3.02 s · cutting 3.02 s · rapid 0 s · 1 break costs 21 ms"]),
        "{context}"
    );

    let explain = Command::new(env!("CARGO_BIN_EXE_ncc")).args(["explain", "G01"]).output().unwrap();
    let explain = String::from_utf8(explain.stdout).unwrap();
    let [hover] = output["hover"].as_array().unwrap().as_slice() else { panic!("one hover answer: {context}") };
    assert_eq!(hover["kind"], "markdown", "{context}");
    // The catalogue's text, then the modal state before the block.
    let value = hover["value"].as_str().unwrap_or_default();
    assert!(value.starts_with(explain.trim()), "{context}");
    assert!(value.contains("**Modal state before this block:**"), "{context}");
}
