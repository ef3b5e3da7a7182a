//! `ncc check`: find partprograms, check them in parallel, report.

use std::{
    collections::{BTreeMap, HashMap, HashSet},
    io::{self, IsTerminal, Write},
    path::{Path, PathBuf},
    process::ExitCode,
};

use indicatif::{ParallelProgressIterator, ProgressBar, ProgressStyle};
use ncc_analysis::{AnalysisHost, Config, Dialect, Dialects, Severity};
pub(crate) use ncc_catalog::macrocycle_number;
use ncc_syntax::{encoding, visible};
use rayon::prelude::*;

use crate::{
    report::{self, Checked, CheckedFile},
    sarif,
};

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Format {
    /// Reports with source snippets, for people.
    Human,
    /// One line per diagnostic: `file:line:col: severity[code]: message`.
    Short,
    /// One JSON array of diagnostics, for tools (a stable contract).
    Json,
    /// SARIF 2.1.0, for code-scanning services.
    Sarif,
}

/// A path as people are shown it: control characters escaped.
pub(crate) fn shown_path(path: &Path) -> String {
    visible::escaped(&path.display().to_string()).into_owned()
}

/// Reads a program file; bytes that are not UTF-8 are read as Kamenický, so
/// every file can be read (see `ncc_syntax::encoding`).
pub(crate) fn read_program(path: &Path) -> io::Result<String> {
    Ok(encoding::decode(read_file(path)?).0)
}

/// Reads a regular file (through symbolic links). Anything else is refused
/// with what it is: a named pipe would wait for a writer forever, and a
/// device may never end.
pub(crate) fn read_file(path: &Path) -> io::Result<Vec<u8>> {
    let kind = std::fs::metadata(path)?.file_type();
    if kind.is_dir() {
        return Err(io::Error::new(io::ErrorKind::IsADirectory, "a directory, not a file"));
    }
    if !kind.is_file() {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("{}, not a regular file", special_kind(kind))));
    }
    std::fs::read(path)
}

/// What a file that is neither a regular file nor a directory is.
fn special_kind(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe (FIFO)";
        } else if kind.is_char_device() {
            return "a character device";
        } else if kind.is_block_device() {
            return "a block device";
        } else if kind.is_socket() {
            return "a socket";
        }
    }
    let _ = kind;
    "a special file"
}

/// A workspace: the `ncc.toml` of a project, and a dialect.
type Workspace = (Option<PathBuf>, Dialect);

/// Below this many files a run is quick enough not to need a progress bar.
const PROGRESS_BAR_MIN_FILES: usize = 200;

/// Reads an `ncc.toml` and the machine and table files it names; the error
/// names the file.
pub(crate) fn load_config(path: &Path) -> Result<Config, String> {
    read_file(path)
        .and_then(|bytes| String::from_utf8(bytes).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e)))
        .map_err(|e| format!("{}: {e}", path.display()))
        .and_then(|text| Config::from_toml(&text, path, read_program))
}

/// The projects met: for each directory the `ncc.toml` that applies, and
/// each such file's configuration (or why it cannot be read), loaded once.
#[derive(Debug, Default)]
pub(crate) struct Projects {
    /// The configuration file that applies to every file, when one is named.
    forced_config: Option<PathBuf>,
    config_of_directory: HashMap<PathBuf, Option<PathBuf>>,
    configs: HashMap<Option<PathBuf>, Result<Config, String>>,
}

impl Projects {
    /// Projects that all have the configuration in `forced_config`, when
    /// one is named.
    pub fn with_config(forced_config: Option<PathBuf>) -> Projects {
        Projects { forced_config, ..Projects::default() }
    }

    /// The `ncc.toml` that applies to the file at `path`; to a text that is
    /// no file (`None`), only a configuration named for every file.
    pub fn config_path(&mut self, path: Option<&Path>) -> Option<PathBuf> {
        let Some(path) = path.filter(|_| self.forced_config.is_none()) else {
            return self.forced_config.clone();
        };
        let directory = path.parent().unwrap_or(Path::new("")).to_path_buf();
        self.config_of_directory.entry(directory).or_insert_with(|| Config::find_for(path)).clone()
    }

    /// The configuration in `config_path`, the defaults for `None`.
    pub fn config(&mut self, config_path: Option<&Path>) -> &Result<Config, String> {
        self.configs
            .entry(config_path.map(Path::to_path_buf))
            .or_insert_with(|| config_path.map_or_else(|| Ok(Config::default()), load_config))
    }

    /// What the project of the file at `path` says of dialects; a project
    /// whose configuration cannot be read says nothing (reading it reports
    /// the error).
    pub fn dialects(&mut self, path: Option<&Path>) -> Dialects {
        let config_path = self.config_path(path);
        self.config(config_path.as_deref()).as_ref().map(|config| config.dialects.clone()).unwrap_or_default()
    }
}

/// The dialect of a program given by name (see [`Dialects::of_given`]).
pub(crate) fn dialect_for(projects: &mut Projects, path: &Path, forced: Option<Dialect>) -> Dialect {
    projects.dialects(Some(path)).of_given(path, forced)
}

pub(crate) fn run(paths: &[PathBuf], format: Format, forced: Option<Dialect>) -> ExitCode {
    let mut projects = Projects::default();
    let Found { files, mut failures } = collect_files(paths, &mut projects, forced);
    let progress = progress_bar(files.len());
    let read: Vec<Result<(PathBuf, Dialect, String), String>> = files
        .par_iter()
        .map(|(path, dialect)| {
            read_program(path)
                .map(|text| (path.clone(), *dialect, text))
                .map_err(|e| format!("{}: {e}", path.display()))
        })
        .collect();

    // The files of one dialect under the same `ncc.toml` form one workspace.
    let mut workspaces: BTreeMap<Workspace, Vec<(PathBuf, String)>> = BTreeMap::new();
    for result in read {
        match result {
            Ok((path, dialect, text)) => {
                workspaces.entry((projects.config_path(Some(&path)), dialect)).or_default().push((path, text))
            }
            Err(message) => failures.push(message),
        }
    }
    let mut checked = Vec::new();
    let mut sources = HashMap::new();
    for ((config_path, dialect), programs) in workspaces {
        let Some(mut host) = workspace_host(&mut projects, config_path.as_deref(), dialect, &mut failures) else {
            continue;
        };
        // Macrocycle files beside the checked programs are what their G72
        // calls run, so they are part of the workspace even when they are
        // not checked themselves.
        let context: Vec<_> = macrocycles_beside(&programs)
            .into_iter()
            .map(|(path, text)| host.add_file(path.display().to_string(), text))
            .collect();
        let ids: Vec<_> =
            programs.into_iter().map(|(path, text)| (host.add_file(path.display().to_string(), text), path)).collect();
        let analysis = host.analysis();
        for &file in context.iter().chain(ids.iter().map(|(file, _)| file)) {
            sources.insert(analysis.path(file), analysis.text(file));
        }
        checked.par_extend(ids.into_par_iter().progress_with(progress.clone()).map_with(
            analysis,
            |analysis, (file, path)| CheckedFile {
                path,
                text: analysis.text(file),
                diagnostics: analysis.diagnostics(file),
            },
        ));
    }
    progress.finish_and_clear();
    checked.sort_by(|a, b| a.path.cmp(&b.path));
    let checked = Checked { files: checked, sources };

    let stdout = io::stdout();
    let color = stdout.is_terminal();
    let mut out = io::BufWriter::new(stdout.lock());
    let written = match format {
        Format::Human => report::write_human(&mut out, &checked, color),
        Format::Short => report::write_short(&mut out, &checked),
        Format::Json => report::write_json(&mut out, &checked),
        Format::Sarif => sarif::write(&mut out, &checked),
    };
    if let Err(error) = written.and_then(|()| out.flush()) {
        if error.kind() != io::ErrorKind::BrokenPipe {
            eprintln!("error: writing the report: {error}");
        }
        return ExitCode::from(2);
    }
    for failure in &failures {
        // Line by line: a TOML error points at its line with a few of its own.
        let lines: Vec<_> = failure.lines().map(visible::escaped).collect();
        eprintln!("error: {}", lines.join("\n"));
    }
    exit_code(&checked, &failures)
}

/// The analysis of the programs of `dialect` under the `ncc.toml` at
/// `config_path`; `None`, with the reason in `failures`, when that file
/// cannot be read.
pub(crate) fn workspace_host(
    projects: &mut Projects,
    config_path: Option<&Path>,
    dialect: Dialect,
    failures: &mut Vec<String>,
) -> Option<AnalysisHost> {
    match projects.config(config_path) {
        Ok(config) => Some(AnalysisHost::in_dialect(dialect, config.clone())),
        Err(message) => {
            failures.push(message.clone());
            None
        }
    }
}

/// 2 when something could not be read, 1 when an error or a warning was
/// found, 0 otherwise (infos and hints are advice, not findings).
fn exit_code(checked: &Checked, failures: &[String]) -> ExitCode {
    if !failures.is_empty() {
        ExitCode::from(2)
    } else if checked.files.iter().flat_map(|f| &f.diagnostics).any(|d| d.severity >= Severity::Warning) {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// A progress bar on stderr for runs large enough to take a while, only
/// when a person is watching.
fn progress_bar(files: usize) -> ProgressBar {
    if files < PROGRESS_BAR_MIN_FILES || !io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(files as u64);
    if let Ok(style) = ProgressStyle::with_template("{spinner} checking {pos}/{len} files {wide_bar} {eta}") {
        bar.set_style(style);
    }
    bar
}

/// Macrocycle files in the directories of `programs` that are not among them.
pub(crate) fn macrocycles_beside(programs: &[(PathBuf, String)]) -> Vec<(PathBuf, String)> {
    let given: HashSet<&Path> = programs.iter().map(|(path, _)| path.as_path()).collect();
    let mut directories: Vec<&Path> = programs.iter().filter_map(|(path, _)| path.parent()).collect();
    directories.sort();
    directories.dedup();
    let mut found = Vec::new();
    for directory in directories {
        let Ok(entries) = std::fs::read_dir(if directory.as_os_str().is_empty() { Path::new(".") } else { directory })
        else {
            continue;
        };
        for entry in entries.flatten() {
            let path = directory.join(entry.file_name());
            if is_macrocycle(&path)
                && !given.contains(path.as_path())
                && path.is_file()
                && let Ok(text) = read_program(&path)
            {
                found.push((path, text));
            }
        }
    }
    found.sort();
    found
}

/// What [`collect_files`] found.
pub(crate) struct Found {
    /// The programs to read, sorted, with their dialect.
    pub files: Vec<(PathBuf, Dialect)>,
    /// Why paths cannot be looked at.
    pub failures: Vec<String>,
}

/// The programs to check: explicit files as given, and in directories the
/// files that are programs of a dialect by their project's configuration or
/// their name. Reading a file that is not a regular one fails later, saying
/// what it is.
pub(crate) fn collect_files(paths: &[PathBuf], projects: &mut Projects, forced: Option<Dialect>) -> Found {
    let mut found = Found { files: Vec::new(), failures: Vec::new() };
    for path in paths {
        let metadata = match std::fs::metadata(path) {
            Ok(metadata) => metadata,
            Err(error) => {
                found.failures.push(format!("{}: {error}", path.display()));
                continue;
            }
        };
        if !metadata.is_dir() {
            found.files.push((path.clone(), projects.dialects(Some(path)).of_given(path, forced)));
            continue;
        }
        for entry in ignore::WalkBuilder::new(path).build() {
            match entry {
                Ok(entry) if entry.file_type().is_some_and(|t| t.is_file()) => {
                    if let Some(dialect) = projects.dialects(Some(entry.path())).of_found(entry.path(), forced) {
                        found.files.push((entry.into_path(), dialect));
                    }
                }
                Ok(_) => {}
                Err(error) => found.failures.push(error.to_string()),
            }
        }
    }
    found.files.sort();
    found.files.dedup_by(|(a, _), (b, _)| a == b);
    found
}

/// Macrocycle files: `L<number>`, with or without an extension.
fn is_macrocycle(path: &Path) -> bool {
    macrocycle_number(path).is_some()
}
