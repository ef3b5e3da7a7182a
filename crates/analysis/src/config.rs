//! The project configuration, `ncc.toml`: rule severities and the machine.
//!
//! ```toml
//! dialect = "cnc8x6"           # every program here is in this dialect
//!
//! [extensions]                 # else a file's extension names its dialect
//! PRG = "cnc8x6"               # (defaults: NCP and L<n> cnc8x6, MPF and SPF
//!                              #  sinumerik, nc and tap haas-lathe)
//!
//! [rules]
//! missing-feed = "warning"     # by name or by code
//! S009 = "off"
//! non-canonical-word-order = "info"   # opt-in rules are off until named
//!
//! [report]
//! max-findings = 1000          # a file's findings shown at most
//!
//! [sinumerik]
//! globals = ["VAC_POLE"]       # names declared outside the file (GUD, macros)
//! r-parameters = 100           # $MN_MM_NUM_R_PARAM: R0 to R99
//! tool-management = true       # the machine manages its tools (GETSELT, GETEXET)
//! stock-top = "0"              # the stock's top on the tool axis, in the program's coordinates
//! cycle-version = "classic"    # whose cycle argument lists calls must fit
//! ball-nose-tools = ["BALL_6", "12"]   # tools (names, numbers) with a ball end
//!
//! [machine]
//! file = "machines/mill.toml"             # a machine file; the keys below override it
//! axes = ["X", "Y", "Z", "U", "V", "C"]   # letters of axes 1-6
//! feed-limit = 24000                      # mm/min
//! rapid-rate = 10000                      # mm/min, every axis (G00)
//! rapid-rates = { Z = 8000 }              # mm/min, axes with a rate of their own
//! limits = { X = { min = "-10", max = "500.5" } }   # mm from the machine zero
//! block-pause-ms = 20                     # between blocks under G98
//! settle-time-ms = 10                     # in-position wait after a stop
//! m-function-ms = 200                     # each M function (M03, M08, …)
//! tool-change-ms = 6000                   # M06
//! look-ahead-blocks = 500                 # envelope velocity (CNC8x9): blocks planned ahead
//! envelope-tick-us = 2000                 # envelope velocity: interpolator tick Ts
//! feed-acceleration = 1000                # Haas lathe, Sinumerik: mm/s², working feed
//! rapid-acceleration = 1000               # Haas lathe: mm/s², G00
//! spindle-acceleration = 1000             # Haas lathe: rpm/s
//! corner-rounding = "0.05"                # Haas lathe: Setting 85, mm
//! cycle-file = "PCYKLYDG.NCP"             # CNC836.KNF $17: what G81-G89 do
//! offset-file = "TAB0.POS"                # zero offsets G53-G59
//! tool-file = "TAB0.KOR"                  # tool corrections D1-D99
//!
//! [machine.work-offsets]                   # Haas lathe: G54-G59, G110-G129
//! G54 = { X = "0", Z = "-250.5" }          # mm from the machine zero, X a diameter
//!
//! [machine.tool-offsets]                   # Haas lathe: the offset yy of Txxyy
//! 1 = { radius = "0.8", tip = 3 }          # nose radius (mm) and tip code 0-9
//! T1D1 = { radius = "5" }                  # Sinumerik: tool T1's edge D1, radius mm
//!
//! [machine.constants]                      # as in TAB0.REK
//! R339 = "01000000"                        # the eight decades
//! R39 = "60.000"                           # or with the decimal point
//! ```
//!
//! A machine file has the keys of `[machine]` except `file`, at its top
//! level. Paths are relative to the file that writes them. Keys in
//! `ncc.toml` replace the machine file's, and within `rapid-rates`,
//! `limits` and `constants` key by key. Every mistake is an error that names
//! the file, and the key or the line and column of a table file
//! (`nc_exec::cnc8x6::tables` has their formats); `docs/machine.md` documents every
//! key.

use std::{
    collections::BTreeMap,
    io,
    path::{Path, PathBuf},
};

pub use nc_exec::machine::{MachineConfig, OffsetTable, ToolTable, TravelLimits, parse_constant};
use nc_exec::{
    cnc8x6::tables::{self, Finding},
    haas_lathe::offsets,
    machine::ToolEntry,
    sinumerik,
};
use ncc_syntax::{Dialect, Severity};
use serde::Deserialize;

use crate::Diagnostic;

/// The name of the project file, looked for from a program's directory up.
pub const CONFIG_FILE: &str = "ncc.toml";

/// What a rule's diagnostics become.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    Off,
    Hint,
    Info,
    Warning,
    Error,
}

impl Level {
    fn severity(self) -> Option<Severity> {
        match self {
            Level::Off => None,
            Level::Hint => Some(Severity::Hint),
            Level::Info => Some(Severity::Info),
            Level::Warning => Some(Severity::Warning),
            Level::Error => Some(Severity::Error),
        }
    }
}

/// Everything configurable about an analysis.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Config {
    pub dialects: Dialects,
    /// Severity overrides by rule code or name.
    pub rules: BTreeMap<String, Level>,
    pub report: ReportConfig,
    pub machine: MachineConfig,
    pub sinumerik: SinumerikConfig,
    pub format: FormatConfig,
}

/// Which dialect a program is in: `dialect` and `[extensions]` in
/// `ncc.toml`.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Dialects {
    /// The dialect of every program, when the project names one.
    pub dialect: Option<Dialect>,
    /// Dialects by file extension (without the dot, any case), before the
    /// defaults.
    pub extensions: BTreeMap<String, Dialect>,
}

impl Dialects {
    /// The dialect the name of the file at `path` gives: its extension as
    /// `[extensions]` maps it, else by default; `None` for a file that is
    /// no program by its name.
    pub fn by_name(&self, path: &Path) -> Option<Dialect> {
        let mapped = || {
            let extension = path.extension()?.to_str()?;
            self.extensions.iter().find(|(known, _)| known.eq_ignore_ascii_case(extension)).map(|(_, &dialect)| dialect)
        };
        mapped().or_else(|| Dialect::by_default_for(path))
    }

    /// The dialect of a file found in a directory, `None` when it is no
    /// program by its name: `forced` (`--dialect`), else the project's,
    /// else the one its name gives.
    pub fn of_found(&self, path: &Path, forced: Option<Dialect>) -> Option<Dialect> {
        self.by_name(path).map(|by_name| forced.or(self.dialect).unwrap_or(by_name))
    }

    /// The dialect of a program given by name: as a found one's, and
    /// CNC8x6 for a name that says nothing.
    pub fn of_given(&self, path: &Path, forced: Option<Dialect>) -> Dialect {
        forced.or(self.dialect).or_else(|| self.by_name(path)).unwrap_or_default()
    }
}

/// The `[report]` section of `ncc.toml`: how much a report shows.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case", default)]
pub struct ReportConfig {
    /// The most findings shown of a file; one more finding counts the rest.
    pub max_findings: usize,
}

impl Default for ReportConfig {
    fn default() -> Self {
        ReportConfig { max_findings: 1000 }
    }
}

/// The `[sinumerik]` section of `ncc.toml`: what a Sinumerik program may
/// use without declaring it.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case", default)]
pub struct SinumerikConfig {
    /// Names declared outside the files (global user data, definitions of
    /// the machine builder), in any case.
    pub globals: Vec<String>,
    /// How many R parameters the control has (`$MN_MM_NUM_R_PARAM`);
    /// `None`: the catalogue's count.
    pub r_parameters: Option<u32>,
    /// The control runs tool management, where `$P_TOOLNO` and `$P_TOOLP`
    /// do not give the tool (004:3274-3280).
    pub tool_management: bool,
    /// The top of the stock on the tool axis in the program's coordinates,
    /// in µm, for `rapid-into-stock`: a program does not say where it is.
    #[serde(deserialize_with = "micrometres")]
    pub stock_top: Option<i32>,
    /// The version of the control's cycles, whose argument lists a call
    /// must fit (004:3298-3302); `None`: not checked.
    pub cycle_version: Option<CycleVersion>,
    /// The tools with a ball end, by name (`T="BALL_6"`) or number, in any
    /// case: a program does not say a tool's shape.
    pub ball_nose_tools: Vec<String>,
}

/// The `[format]` section of `ncc.toml`: the style `ncc fmt` and the
/// editor's formatting write. Every choice keeps what the program does;
/// the defaults change spacing only.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case", default)]
pub struct FormatConfig {
    pub spacing: WordSpacing,
    pub case: LetterCase,
    pub numbers: NumberStyle,
    pub word_order: WordOrder,
    /// Spaces per level of nesting that a line is indented by: Sinumerik's
    /// IF, WHILE, FOR, REPEAT and LOOP bodies, the Haas lathe's `WHILE …
    /// DOn` loops (CNC8x6 blocks have no nesting). `None`: each line keeps
    /// its indentation.
    pub indent: Option<u8>,
}

/// What separates the words of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WordSpacing {
    /// One space between the items of a block (`N10 G0 X0`).
    #[default]
    One,
    /// Words written together (`N10G0X0`), as tape-era programs save
    /// memory; other items keep one space. Sinumerik keeps one everywhere:
    /// its names run on until a space.
    None,
}

/// The case of address letters (and, in Sinumerik, of names and keywords,
/// which it reads in any case; strings and comments are kept).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LetterCase {
    #[default]
    Keep,
    Upper,
}

/// How numbers with a decimal point are written; a number without one is
/// never touched, since the point can change what it means (CNC8x6
/// `R1=864` is 0.864, Haas dwell `P30` is 30 ms).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NumberStyle {
    #[default]
    Keep,
    /// Zeros that say nothing go: `X010.500` becomes `X10.5`, `Z-2.000`
    /// `Z-2.0` (one digit after the point stays); codes (`G54.1`) and block
    /// numbers are kept.
    Trim,
}

/// The order of a block's words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WordOrder {
    #[default]
    Keep,
    /// Block number, G codes, axes, arc and corner words, feed, speed,
    /// tool, offset, M codes, then the function's arguments (`P`, `Q`, `L`,
    /// `H`), by the catalogue's address roles. Only blocks of plain words
    /// (a letter and a number) on one line, with no letter twice but the
    /// codes', are reordered: there the control reads the block as a whole.
    Standard,
}

/// A version of Sinumerik's cycles whose argument lists the catalogue has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CycleVersion {
    /// The 840D cycles' classic lists; SINUMERIK Operate adds arguments
    /// after them.
    Classic,
}

/// A length in mm written as text (`"-2.5"`), in µm.
fn micrometres<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<Option<i32>, D::Error> {
    let text: Option<String> = Option::deserialize(deserializer)?;
    text.map(|text| tables::coordinate(&text).map_err(serde::de::Error::custom)).transpose()
}

impl SinumerikConfig {
    /// Whether `name` (upper case) is declared outside the files.
    pub fn is_global(&self, name: &str) -> bool {
        self.globals.iter().any(|global| global.eq_ignore_ascii_case(name))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct ConfigFile {
    dialect: Option<Dialect>,
    #[serde(default)]
    extensions: BTreeMap<String, Dialect>,
    #[serde(default)]
    rules: BTreeMap<String, Level>,
    #[serde(default)]
    report: ReportConfig,
    #[serde(default)]
    sinumerik: SinumerikConfig,
    #[serde(default)]
    format: FormatConfig,
    #[serde(default)]
    machine: Option<MachineFile>,
}

/// The `[machine]` section of `ncc.toml`, and a machine file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct MachineFile {
    /// The machine file these keys override (in `ncc.toml` only).
    file: Option<PathBuf>,
    axes: Option<Vec<String>>,
    feed_limit: Option<u32>,
    rapid_rate: Option<u32>,
    #[serde(default)]
    rapid_rates: BTreeMap<String, u32>,
    #[serde(default)]
    limits: BTreeMap<String, LimitsFile>,
    diameter_axis: Option<String>,
    block_pause_ms: Option<u32>,
    settle_time_ms: Option<u32>,
    m_function_ms: Option<u32>,
    tool_change_ms: Option<u32>,
    look_ahead_blocks: Option<u32>,
    envelope_tick_us: Option<u32>,
    feed_acceleration: Option<u32>,
    rapid_acceleration: Option<u32>,
    spindle_acceleration: Option<u32>,
    corner_rounding: Option<String>,
    cycle_file: Option<String>,
    offset_file: Option<PathBuf>,
    tool_file: Option<PathBuf>,
    #[serde(default)]
    work_offsets: BTreeMap<String, BTreeMap<String, String>>,
    #[serde(default)]
    tool_offsets: BTreeMap<String, ToolOffsetFile>,
    #[serde(default)]
    constants: BTreeMap<String, String>,
}

/// A Haas lathe's tool offset: its nose radius and tip code; a Sinumerik
/// tool's cutting edge: its radius.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolOffsetFile {
    radius: Option<String>,
    tip: Option<u8>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitsFile {
    min: Option<String>,
    max: Option<String>,
}

/// A table file, and the key that names it for errors reading it.
struct TableFile {
    path: PathBuf,
    named_by: String,
}

/// The table files the configuration names, read once the axes are known,
/// and a Haas lathe's work offsets: by G code, each axis's offset by
/// letter, in thousandths.
#[derive(Default)]
struct TableFiles {
    offsets: Option<TableFile>,
    tools: Option<TableFile>,
    work_offsets: BTreeMap<u8, Vec<(u8, i32)>>,
}

impl MachineFile {
    /// Sets what the file gives. `path` is the file's, where its table
    /// paths start from; errors name the keys after `section`.
    fn apply(
        self,
        machine: &mut MachineConfig,
        tables: &mut TableFiles,
        path: &Path,
        section: &str,
    ) -> Result<(), String> {
        let origin = path.display();
        if let Some(axes) = self.axes {
            let letters: Option<Vec<u8>> = axes.iter().map(|axis| axis_letter(axis)).collect();
            match letters {
                Some(letters) if (1..=6).contains(&letters.len()) => machine.axes = letters,
                _ => return Err(format!("{origin}: {section}axes must list one to six axis letters")),
            }
        }
        if let Some(limit) = self.feed_limit {
            machine.feed_limit = limit;
        }
        if let Some(pause) = self.block_pause_ms {
            machine.block_pause_ms = pause;
        }
        if let Some(settle) = self.settle_time_ms {
            machine.settle_time_ms = settle;
        }
        if let Some(time) = self.m_function_ms {
            machine.m_function_ms = time;
        }
        if let Some(time) = self.tool_change_ms {
            machine.tool_change_ms = time;
        }
        if let Some(blocks) = self.look_ahead_blocks {
            if !(1..=500).contains(&blocks) {
                return Err(format!("{origin}: {section}look-ahead-blocks must be 1 to 500 (the control's most)"));
            }
            machine.look_ahead_blocks = blocks;
        }
        if let Some(tick) = self.envelope_tick_us {
            if tick == 0 {
                return Err(format!("{origin}: {section}envelope-tick-us must be above 0 µs"));
            }
            machine.envelope_tick_us = tick;
        }
        let haas = machine.control == Dialect::HaasLathe;
        // The Haas lathe and Sinumerik policies read their ramps from here.
        let reads_ramps = haas || machine.control == Dialect::Sinumerik;
        let ramps = [
            ("feed-acceleration", self.feed_acceleration, &mut machine.feed_acceleration),
            ("rapid-acceleration", self.rapid_acceleration, &mut machine.rapid_acceleration),
            ("spindle-acceleration", self.spindle_acceleration, &mut machine.spindle_acceleration),
        ];
        for (key, value, slot) in ramps {
            let Some(value) = value else { continue };
            if !reads_ramps {
                return Err(format!(
                    "{origin}: {section}{key} describes a Haas lathe or a Sinumerik machine; a CNC8x6 reads its ramps from R52, R236 and R237"
                ));
            }
            if value == 0 {
                return Err(format!("{origin}: {section}{key} must be above 0"));
            }
            *slot = Some(value);
        }
        if let Some(rounding) = self.corner_rounding {
            if !haas {
                return Err(format!(
                    "{origin}: {section}corner-rounding is a Haas lathe's Setting 85 (dialect = \"haas-lathe\")"
                ));
            }
            let value = tables::coordinate(&rounding)
                .ok()
                .and_then(|um| u32::try_from(um).ok())
                .filter(|&um| um > 0)
                .ok_or_else(|| {
                format!("{origin}: {section}corner-rounding `{rounding}` must be a length above 0 mm, to the µm")
            })?;
            machine.corner_rounding_um = Some(value);
        }
        if let Some(rate) = self.rapid_rate {
            if rate == 0 {
                return Err(format!("{origin}: {section}rapid-rate must be above 0 mm/min"));
            }
            machine.rapid_rate = rate;
        }
        for (axis, rate) in self.rapid_rates {
            let letter = axis_letter(&axis)
                .ok_or_else(|| format!("{origin}: {section}rapid-rates key `{axis}` is not an axis letter"))?;
            if rate == 0 {
                return Err(format!("{origin}: {section}rapid-rates.{axis} must be above 0 mm/min"));
            }
            machine.rapid_rates.insert(letter, rate);
        }
        for (axis, limits) in self.limits {
            let letter = axis_letter(&axis)
                .ok_or_else(|| format!("{origin}: {section}limits key `{axis}` is not an axis letter"))?;
            let bound = |value: Option<String>, name: &str| {
                value
                    .map(|value| tables::coordinate(&value))
                    .transpose()
                    .map_err(|e| format!("{origin}: {section}limits.{axis}.{name}: {e}"))
            };
            let limits = TravelLimits { min: bound(limits.min, "min")?, max: bound(limits.max, "max")? };
            if let (Some(min), Some(max)) = (limits.min, limits.max)
                && min > max
            {
                return Err(format!("{origin}: {section}limits.{axis}: min is above max"));
            }
            machine.limits.insert(letter, limits);
        }
        if let Some(axis) = self.diameter_axis {
            let letter = axis_letter(&axis)
                .ok_or_else(|| format!("{origin}: {section}diameter-axis `{axis}` is not an axis letter"))?;
            machine.diameter_axis = Some(letter);
        }
        if let Some(name) = self.cycle_file {
            if name.trim().is_empty() {
                return Err(format!("{origin}: {section}cycle-file must name a file, e.g. \"PCYKLYDG.NCP\""));
            }
            machine.cycle_file = Some(name);
        }
        let table = |key: &str, name: PathBuf| TableFile {
            path: relative_to(path, &name),
            named_by: format!("{origin}: {section}{key} `{}`", name.display()),
        };
        if haas && (self.offset_file.is_some() || self.tool_file.is_some()) {
            return Err(format!(
                "{origin}: {section}offset-file and tool-file are the CNC8x6's tables; a Haas lathe gives work-offsets and tool-offsets"
            ));
        }
        let sinumerik = machine.control == Dialect::Sinumerik;
        let haas_keys = !self.work_offsets.is_empty() || (!self.tool_offsets.is_empty() && !sinumerik);
        if haas_keys && !haas {
            return Err(format!(
                "{origin}: {section}work-offsets and tool-offsets describe a Haas lathe (dialect = \"haas-lathe\") or, tool-offsets only, a Sinumerik's cutting edges; a CNC8x6 reads offset-file and tool-file"
            ));
        }
        if let Some(name) = self.offset_file {
            tables.offsets = Some(table("offset-file", name));
        }
        if let Some(name) = self.tool_file {
            tables.tools = Some(table("tool-file", name));
        }
        for (key, axes) in self.work_offsets {
            let code = offsets::work_offset_code(&key)
                .ok_or_else(|| format!("{origin}: {section}work-offsets key `{key}` is none of G54-G59, G110-G129"))?;
            let mut row = Vec::new();
            for (axis, value) in axes {
                let letter = axis_letter(&axis).ok_or_else(|| {
                    format!("{origin}: {section}work-offsets.{key} key `{axis}` is not an axis letter")
                })?;
                let value = tables::coordinate(&value)
                    .map_err(|e| format!("{origin}: {section}work-offsets.{key}.{axis}: {e}"))?;
                row.push((letter, value));
            }
            tables.work_offsets.insert(code, row);
        }
        for (key, offset) in self.tool_offsets.iter().filter(|_| sinumerik) {
            let edge = sinumerik::cutting_edge_key(key)
                .ok_or_else(|| format!("{origin}: {section}tool-offsets key `{key}` is no tool edge like `T1D1`"))?;
            let field = |e: String| format!("{origin}: {section}tool-offsets.{key}: {e}");
            if offset.tip.is_some() {
                return Err(field("a tip code is a lathe's; a Sinumerik edge gives its radius".to_owned()));
            }
            let radius = offset.radius.as_deref().map(tables::coordinate).transpose().map_err(field)?.unwrap_or(0);
            if radius < 0 {
                return Err(field("the radius must not be negative".to_owned()));
            }
            machine.cutting_edges.insert(edge, ToolEntry { radius, ..ToolEntry::default() });
        }
        for (key, offset) in self.tool_offsets.into_iter().filter(|_| !sinumerik) {
            let number = offsets::tool_offset_number(&key)
                .ok_or_else(|| format!("{origin}: {section}tool-offsets key `{key}` is no offset number 1-99"))?;
            let field = |e: String| format!("{origin}: {section}tool-offsets.{key}: {e}");
            let radius = offset.radius.map(|radius| tables::coordinate(&radius)).transpose().map_err(field)?;
            let entry = offsets::tool_offset(radius.unwrap_or(0), offset.tip).map_err(field)?;
            machine.tools.entries.insert(number, entry);
        }
        for (name, value) in self.constants {
            let number = name
                .strip_prefix(['R', 'r'])
                .and_then(|n| n.parse().ok())
                .ok_or_else(|| format!("{origin}: {section}constants key `{name}` is not like `R339`"))?;
            let raw = parse_constant(&value)
                .ok_or_else(|| format!("{origin}: {section}constants.{name} = `{value}` is not a number"))?;
            machine.constants.insert(number, raw);
        }
        Ok(())
    }
}

impl TableFile {
    /// Reads the table with `parse`; a line it does not understand is an
    /// error located in the table file.
    fn read<T>(
        self,
        read: impl Fn(&Path) -> io::Result<String>,
        axes: &[u8],
        parse: fn(&str, &[u8]) -> (T, Vec<Finding>),
    ) -> Result<T, String> {
        let text = read(&self.path).map_err(|e| format!("{}: {e}", self.named_by))?;
        let (table, findings) = parse(&text, axes);
        if findings.is_empty() {
            return Ok(table);
        }
        let lines: Vec<String> = findings.iter().map(|finding| format!("{}:{finding}", self.path.display())).collect();
        Err(lines.join("\n"))
    }
}

/// A letter as configuration keys write an axis: `"X"`, or `"x"`.
fn axis_letter(text: &str) -> Option<u8> {
    match *text.as_bytes() {
        [letter] if letter.is_ascii_alphabetic() => Some(letter.to_ascii_uppercase()),
        _ => None,
    }
}

/// Rates and limits may be given only for the machine's axes, which may
/// come from another file than they do.
fn check_axis_keys(machine: &MachineConfig) -> Result<(), String> {
    let rates = machine.rapid_rates.keys().map(|&letter| ("rapid-rates", letter));
    let limits = machine.limits.keys().map(|&letter| ("limits", letter));
    let diameter = machine.diameter_axis.map(|letter| ("diameter-axis", letter));
    match rates.chain(limits).chain(diameter).find(|&(_, letter)| !machine.is_axis(letter)) {
        Some((key, letter)) => Err(format!(
            "the machine's {key} name `{}`, which is not an axis of it ({})",
            char::from(letter),
            tables::axis_list(&machine.axes)
        )),
        None => Ok(()),
    }
}

/// `name` as written in the file at `path`: relative to its directory.
fn relative_to(path: &Path, name: &Path) -> PathBuf {
    path.parent().unwrap_or(Path::new("")).join(name)
}

impl Config {
    /// This configuration for the programs of `dialect`: a machine
    /// described for another control (a project that names no dialect
    /// describes a CNC8x6 machine) gives way to `dialect`'s default one.
    pub fn for_dialect(mut self, dialect: Dialect) -> Config {
        if self.machine.control != dialect {
            self.machine = MachineConfig::of_control(dialect);
        }
        self
    }

    /// Reads `ncc.toml`'s text. `path` names the file in errors and is where
    /// the paths it holds start from; `read` reads the files they name.
    pub fn from_toml(text: &str, path: &Path, read: impl Fn(&Path) -> io::Result<String>) -> Result<Config, String> {
        let origin = path.display().to_string();
        let file: ConfigFile = toml::from_str(text).map_err(|e| format!("{origin}: {e}"))?;
        let mut extensions = BTreeMap::new();
        for (extension, dialect) in file.extensions {
            let bare = extension.strip_prefix('.').unwrap_or(&extension);
            if bare.is_empty() || bare.contains(['.', '/', '\\']) {
                return Err(format!("{origin}: [extensions] key `{extension}` is not a file extension like `NCP`"));
            }
            extensions.insert(bare.to_owned(), dialect);
        }
        let mut config = Config {
            dialects: Dialects { dialect: file.dialect, extensions },
            rules: file.rules,
            report: file.report,
            sinumerik: file.sinumerik,
            format: file.format,
            // The machine's control is the project's dialect when this
            // build reads it; the machine's keys are read in its terms.
            machine: MachineConfig::of_control(file.dialect.unwrap_or_default()),
        };
        if let Some(unknown) = config.rules.keys().find(|key| crate::Rule::find(key).is_none()) {
            return Err(format!("{origin}: [rules] names no rule `{unknown}` (see `ncc rules`)"));
        }
        let Some(mut keys) = file.machine else {
            return Ok(config);
        };
        let mut tables = TableFiles::default();
        if let Some(name) = keys.file.take() {
            let machine_path = relative_to(path, &name);
            let machine_origin = machine_path.display().to_string();
            let text = read(&machine_path).map_err(|e| format!("{origin}: machine.file `{}`: {e}", name.display()))?;
            let machine: MachineFile = toml::from_str(&text).map_err(|e| format!("{machine_origin}: {e}"))?;
            if machine.file.is_some() {
                return Err(format!("{machine_origin}: a machine file cannot name another (`file`)"));
            }
            machine.apply(&mut config.machine, &mut tables, &machine_path, "")?;
        }
        keys.apply(&mut config.machine, &mut tables, path, "machine.")?;
        check_axis_keys(&config.machine).map_err(|e| format!("{origin}: {e}"))?;
        if let Some(table) = tables.offsets {
            config.machine.offsets = table.read(&read, &config.machine.axes, OffsetTable::parse)?;
        }
        if let Some(table) = tables.tools {
            config.machine.tools = table.read(&read, &config.machine.axes, ToolTable::parse)?;
        }
        for (code, row) in tables.work_offsets {
            let mut values = [0; 6];
            for (letter, value) in row {
                let index = config.machine.axes.iter().position(|&axis| axis == letter).ok_or_else(|| {
                    let axes = tables::axis_list(&config.machine.axes);
                    format!(
                        "{origin}: machine.work-offsets.G{code}: `{}` is not an axis of the machine ({axes})",
                        char::from(letter)
                    )
                })?;
                values[index] = value;
            }
            config.machine.offsets.rows.insert(code, values);
        }
        Ok(config)
    }

    /// The `ncc.toml` that applies to `path`: the nearest one in its
    /// directory or above.
    pub fn find_for(path: &Path) -> Option<PathBuf> {
        let start = if path.is_dir() { path } else { path.parent()? };
        let start = if start.as_os_str().is_empty() { Path::new(".") } else { start };
        let start = start.canonicalize().ok()?;
        start.ancestors().map(|dir| dir.join(CONFIG_FILE)).find(|candidate| candidate.is_file())
    }

    /// Applies the severity overrides; `None` when the rule is turned off,
    /// or is an opt-in rule the configuration does not name.
    pub(crate) fn adjust(&self, mut diagnostic: Diagnostic) -> Option<Diagnostic> {
        diagnostic.severity = self.severity(diagnostic.code, diagnostic.name, diagnostic.severity)?;
        Some(diagnostic)
    }

    /// What a finding of `rule` becomes: `None` when it is off.
    pub fn level_of(&self, rule: &crate::Rule) -> Option<Severity> {
        self.severity(rule.code, rule.name, rule.severity)
    }

    /// What a finding of rule `code` (`name`) found at `severity` becomes.
    pub(crate) fn severity(&self, code: &str, name: &str, severity: Severity) -> Option<Severity> {
        match self.rules.get(code).or_else(|| self.rules.get(name)) {
            None if crate::Rule::find(code).is_some_and(|rule| rule.opt_in) => None,
            None => Some(severity),
            Some(level) => level.severity(),
        }
    }
}

#[cfg(test)]
mod tests {
    use expect_test::expect;

    use super::*;

    /// Loads `project/ncc.toml` with `text`, beside the other `files`.
    fn load(text: &str, files: &[(&str, &str)]) -> Result<Config, String> {
        let read = |path: &Path| {
            let file = files.iter().find(|(name, _)| Path::new(name) == path);
            file.map(|(_, text)| text.to_string()).ok_or_else(|| io::ErrorKind::NotFound.into())
        };
        Config::from_toml(text, Path::new("project/ncc.toml"), read)
    }

    #[test]
    fn reads_rules_and_machine() {
        let config = load(
            "[rules]\nS009 = \"off\"\nunknown-code = \"warning\"\n[machine]\naxes = [\"X\", \"Z\"]\nfeed-limit = 10000\nrapid-rate = 15000\n[machine.constants]\nR339 = \"01000000\"\nR39 = \"45.5\"\n",
            &[],
        )
        .unwrap();
        assert_eq!(config.rules.get("S009"), Some(&Level::Off));
        assert_eq!(config.machine.axes, b"XZ");
        assert_eq!(config.machine.feed_limit, 10_000);
        assert_eq!(config.machine.rapid_rate, 15_000);
        assert_eq!(config.machine.decade(339, 7), 1);
        assert_eq!(config.machine.constant(39), 45_500);
    }

    #[test]
    fn rejects_mistakes_with_a_clear_message() {
        let error = load("[rules]\nno-such-rule = \"off\"\n", &[]).unwrap_err();
        assert!(error.contains("no-such-rule"), "{error}");
        let error = load("[machine]\naxes = [\"XY\"]\n", &[]).unwrap_err();
        assert!(error.contains("axis letters"), "{error}");
        assert!(load("[machine.constants]\nR39 = \"abc\"\n", &[]).is_err());
        assert!(load("[unknown]\n", &[]).is_err());
        let error = load("[machine]\nrapid-rate = 0\n", &[]).unwrap_err();
        assert!(error.contains("rapid-rate"), "{error}");
    }

    #[test]
    fn a_haas_lathe_gives_its_work_and_tool_offsets() {
        let ncc = "dialect = \"haas-lathe\"\n[machine]\nfile = \"lathe.toml\"\n[machine.work-offsets]\nG55 = { Z = \"-300\" }\n";
        let lathe = "[work-offsets]\nG54 = { X = \"-100.5\", Z = \"-250\" }\nG110 = { Z = \"5\" }\n[tool-offsets]\n1 = { radius = \"0.8\", tip = 3 }\n12 = { tip = 8 }\n";
        let machine = load(ncc, &[("project/lathe.toml", lathe)]).unwrap().machine;
        assert_eq!(machine.axes, b"XZ");
        // X as written, a diameter; rows by G code, per axis.
        assert_eq!(machine.offsets.offset(54), [-100_500, -250_000, 0, 0, 0, 0]);
        assert_eq!(machine.offsets.offset(55), [0, -300_000, 0, 0, 0, 0]);
        assert_eq!(machine.offsets.offset(110), [0, 5_000, 0, 0, 0, 0]);
        assert_eq!((machine.tools.entry(1).radius, machine.tools.entry(1).tip), (800, Some(3)));
        assert_eq!((machine.tools.entry(12).radius, machine.tools.entry(12).tip), (0, Some(8)));
        let haas = |keys: &str| load(&format!("dialect = \"haas-lathe\"\n[machine]\n{keys}"), &[]).unwrap_err();
        for (keys, says) in [
            ("[machine.work-offsets]\nG53 = { Z = \"1\" }\n", "G53"),
            ("[machine.work-offsets]\nG54 = { Y = \"1\" }\n", "`Y` is not an axis"),
            ("[machine.tool-offsets]\n100 = { tip = 3 }\n", "100"),
            ("[machine.tool-offsets]\n1 = { tip = 10 }\n", "tip code"),
            ("[machine.tool-offsets]\n1 = { radius = \"-0.4\" }\n", "negative"),
            ("tool-file = \"TAB0.KOR\"\n", "tool-offsets"),
        ] {
            let error = haas(keys);
            assert!(error.contains(says), "{keys}: {error}");
        }
        let error = load("[machine.tool-offsets]\n1 = { tip = 3 }\n", &[]).unwrap_err();
        assert!(error.contains("haas-lathe"), "{error}");
    }

    #[test]
    fn a_sinumerik_gives_its_tools_cutting_edges() {
        let keys = "dialect = \"sinumerik\"\n[machine.tool-offsets]\nT1D1 = { radius = \"5\" }\nT12D2 = { radius = \"0.4\" }\n";
        let machine = load(keys, &[]).unwrap().machine;
        let radii: Vec<_> = machine.cutting_edges.iter().map(|(&edge, entry)| (edge, entry.radius)).collect();
        assert_eq!(radii, [((1, 1), 5000), ((12, 2), 400)]);
        for (offset, says) in [
            ("1 = { radius = \"5\" }", "`1`"),
            ("T1D0 = { radius = \"5\" }", "`T1D0`"),
            ("T1D1 = { radius = \"5\", tip = 3 }", "tip"),
            ("T1D1 = { radius = \"-5\" }", "negative"),
        ] {
            let error = load(&format!("dialect = \"sinumerik\"\n[machine.tool-offsets]\n{offset}\n"), &[]).unwrap_err();
            assert!(error.contains(says), "{offset}: {error}");
        }
    }

    #[test]
    fn a_haas_lathe_gives_its_ramps_spindle_and_setting_85() {
        let keys = "feed-acceleration = 800\nrapid-acceleration = 2500\nspindle-acceleration = 600\ncorner-rounding = \"0.02\"\n";
        let machine = load(&format!("dialect = \"haas-lathe\"\n[machine]\n{keys}"), &[]).unwrap().machine;
        assert_eq!((machine.feed_acceleration, machine.rapid_acceleration), (Some(800), Some(2500)));
        assert_eq!((machine.spindle_acceleration, machine.corner_rounding_um), (Some(600), Some(20)));
        let haas = |keys: &str| load(&format!("dialect = \"haas-lathe\"\n[machine]\n{keys}"), &[]).unwrap_err();
        for (keys, says) in [
            ("feed-acceleration = 0\n", "feed-acceleration must be above 0"),
            ("corner-rounding = \"0\"\n", "above 0 mm"),
            ("corner-rounding = \"-0.1\"\n", "above 0 mm"),
            ("corner-rounding = \"0.0001\"\n", "to the µm"),
        ] {
            let error = haas(keys);
            assert!(error.contains(says), "{keys}: {error}");
        }
        let error = load("[machine]\nrapid-acceleration = 1000\n", &[]).unwrap_err();
        assert!(error.contains("R52, R236 and R237"), "{error}");
        // A Sinumerik machine's policy reads the ramps too.
        let sinumerik = load("dialect = \"sinumerik\"\n[machine]\nfeed-acceleration = 700\n", &[]).unwrap().machine;
        assert_eq!(sinumerik.feed_acceleration, Some(700));
        let error = load("[machine]\ncorner-rounding = \"0.1\"\n", &[]).unwrap_err();
        assert!(error.contains("Setting 85"), "{error}");
    }

    #[test]
    fn defaults_come_from_the_catalogue() {
        let machine = MachineConfig::default();
        assert_eq!(machine.constant(39), 60_000, "R39 default 60.000");
        assert_eq!(machine.constant(339), 0);
    }

    const MILL: &str = r#"
axes = ["X", "Y", "Z"]
rapid-rate = 20000
rapid-rates = { Z = 8000 }
limits = { X = { min = "-10", max = "500.5" }, Z = { max = "0" } }
cycle-file = "PCYKLYDG.NCP"
offset-file = "TAB0.POS"
tool-file = "TAB0.KOR"
[constants]
R39 = "30.000"
R97 = "2"
"#;

    #[test]
    fn a_machine_file_gives_the_machine_and_ncc_toml_overrides_it() {
        let ncc = "[machine]\nfile = \"machines/mill.toml\"\ntool-file = \"TAB1.KOR\"\nrapid-rates = { Y = 12000 }\n[machine.constants]\nR39 = \"45.5\"\n";
        let files = [
            ("project/machines/mill.toml", MILL),
            ("project/machines/TAB0.POS", "$POS\nG54: X=100.5 Y=-20.0\n"),
            ("project/machines/TAB0.KOR", "$KOR\n01: R=5.0\n"),
            ("project/TAB1.KOR", "$KOR\n02: R=0.8 Z=100.0\n"),
        ];
        let machine = load(ncc, &files).unwrap().machine;
        assert_eq!(machine.axes, b"XYZ");
        assert_eq!(
            [b'X', b'Y', b'Z'].map(|letter| machine.axis_rapid_rate(letter)),
            [20_000, 12_000, 8_000],
            "the file's rates, and ncc.toml's for Y"
        );
        assert_eq!(machine.limits[&b'X'], TravelLimits { min: Some(-10_000), max: Some(500_500) });
        assert_eq!(machine.limits[&b'Z'], TravelLimits { min: None, max: Some(0) });
        assert_eq!(machine.cycle_file.as_deref(), Some("PCYKLYDG.NCP"));
        assert_eq!(machine.offsets.offset(54), [100_500, -20_000, 0, 0, 0, 0], "beside the machine file");
        // ncc.toml's tool file, beside ncc.toml, replaces the machine file's.
        assert_eq!(machine.tools.entries.keys().copied().collect::<Vec<_>>(), [2]);
        assert_eq!(machine.tools.entry(2).lengths[2], 100_000);
        assert_eq!((machine.constant(39), machine.constant(97)), (45_500, 2), "constants key by key");
        assert_eq!(machine.diameter_axis, None);
        assert_eq!((machine.block_pause_ms, machine.settle_time_ms), (20, 10), "the defaults");
        let timed = load(
            "[machine]\nblock-pause-ms = 35\nsettle-time-ms = 0\nm-function-ms = 200\ntool-change-ms = 6000\n",
            &[],
        )
        .unwrap()
        .machine;
        assert_eq!((timed.block_pause_ms, timed.settle_time_ms), (35, 0));
        assert_eq!((timed.m_function_ms, timed.tool_change_ms), (200, 6000));
        let envelope = load("[machine]\nlook-ahead-blocks = 50\nenvelope-tick-us = 500\n", &[]).unwrap().machine;
        assert_eq!((envelope.look_ahead_blocks, envelope.envelope_tick_us), (50, 500));
        assert_eq!((machine.look_ahead_blocks, machine.envelope_tick_us), (500, 2000), "the defaults");
        assert!(load("[machine]\nlook-ahead-blocks = 501\n", &[]).is_err());
        assert!(load("[machine]\nenvelope-tick-us = 0\n", &[]).is_err());
        let lathe = load("[machine]\naxes = [\"X\", \"Z\"]\ndiameter-axis = \"x\"\n", &[]).unwrap();
        assert_eq!(lathe.machine.diameter_axis, Some(b'X'));
    }

    #[test]
    fn mistakes_in_machine_and_table_files_name_the_place() {
        let with_file = |machine: &str, files: &[(&str, &str)]| {
            let ncc = format!("[machine]\nfile = \"m.toml\"\n{machine}");
            let mut files = files.to_vec();
            files.push(("project/m.toml", "axes = [\"X\", \"Z\"]\noffset-file = \"POS/TAB0.POS\"\n"));
            load(&ncc, &files).unwrap_err()
        };
        let good_offsets = ("project/POS/TAB0.POS", "$POS\n");
        let errors = [
            load("[machine]\nfile = \"none.toml\"\n", &[]).unwrap_err(),
            load("[machine]\nfile = \"m.toml\"\n", &[("project/m.toml", "axes = [\"X\"\n")]).unwrap_err(),
            load("[machine]\nfile = \"m.toml\"\n", &[("project/m.toml", "file = \"n.toml\"\n")]).unwrap_err(),
            with_file("", &[]),
            with_file("", &[("project/POS/TAB0.POS", "$POS\nG54: X=1.0 Y=2.0\nG60: Z=1.0\n")]),
            with_file("tool-file = \"TAB0.KOR\"\n", &[good_offsets, ("project/TAB0.KOR", "$KOR\n01: Z=1.0\n")]),
            with_file("rapid-rates = { Y = 5000 }\n", &[good_offsets]),
            with_file("diameter-axis = \"Y\"\n", &[good_offsets]),
            with_file("diameter-axis = \"XZ\"\n", &[good_offsets]),
            with_file("[machine.limits]\nX = { min = \"1\", max = \"0\" }\n", &[good_offsets]),
            with_file("[machine.limits]\nX = { min = \"0.0001\" }\n", &[good_offsets]),
        ];
        expect![[r#"
            project/ncc.toml: machine.file `none.toml`: entity not found
            project/m.toml: TOML parse error at line 1, column 12
              |
            1 | axes = ["X"
              |            ^
            unclosed array, expected `]`

            project/m.toml: a machine file cannot name another (`file`)
            project/m.toml: offset-file `POS/TAB0.POS`: entity not found
            project/POS/TAB0.POS:2:12: `Y` is not an axis of this machine (axes X Z)
            project/POS/TAB0.POS:3:1: `G60` names no row: the rows are G53 to G59
            project/TAB0.KOR:2:5: `Z=` corrects axis 3 (the names stand for X, Y, Z, U in that order), but on this machine Z is axis 2: write `2=`
            project/ncc.toml: the machine's rapid-rates name `Y`, which is not an axis of it (axes X Z)
            project/ncc.toml: the machine's diameter-axis name `Y`, which is not an axis of it (axes X Z)
            project/ncc.toml: machine.diameter-axis `XZ` is not an axis letter
            project/ncc.toml: machine.limits.X: min is above max
            project/ncc.toml: machine.limits.X.min: `0.0001` is finer than the control's 0.001"#]].assert_eq(&errors.join("\n"));
    }
}
