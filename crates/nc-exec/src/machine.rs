//! The machine a program runs on: its axes, rates and travel limits, the
//! fixed-cycle file, the machine constants (TAB0.REK) and the tables of
//! zero offsets (TAB0.POS) and tool corrections (TAB0.KOR). The analysis
//! reads it from `ncc.toml` and the machine file it names; the executor
//! runs on it.

use std::collections::BTreeMap;

use ncc_catalog::Dialect;

use ncc_syntax::{Decimal, Sign};

/// The machine the programs run on.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct MachineConfig {
    /// The control: the language its programs are in, and what its
    /// machine constants mean.
    pub control: Dialect,
    /// Letters of axes 1 to 6.
    pub axes: Vec<u8>,
    /// Highest programmable feed in mm/min.
    pub feed_limit: u32,
    /// The rapid traverse (G00) of every axis without a rate of its own, in
    /// mm/min (degrees/min for a rotary axis). The manual makes it a machine
    /// constant without naming one or a value; the default is an assumption.
    pub rapid_rate: u32,
    /// Rapid traverse rates of single axes, by letter.
    pub rapid_rates: BTreeMap<u8, u32>,
    /// Travel limits of single axes, by letter.
    pub limits: BTreeMap<u8, TravelLimits>,
    /// The axis a lathe programs as a diameter under G74 (X); the machine
    /// starts in diameter programming, as the manual's lathe examples do.
    pub diameter_axis: Option<u8>,
    /// Machine constants set in the configuration, as raw values (the
    /// decades as digits: `00233.112` → 233112).
    pub constants: BTreeMap<u32, i64>,
    /// The fixed-cycle file the control loads (parameter `$17` of
    /// CNC836.KNF), e.g. `PCYKLYDG.NCP` (milling) or `PEVNECY5.NCP`
    /// (lathe): it decides what G81–G89 do.
    pub cycle_file: Option<String>,
    /// CNC8x6: the zero offsets G53-G59 as the control loads them from
    /// TAB0.POS. Haas lathe: the work offsets G54-G59 and G110-G129 of the
    /// offset page, X as a diameter.
    pub offsets: OffsetTable,
    /// CNC8x6: the tool corrections D1-D99 as the control loads them from
    /// TAB0.KOR. Haas lathe: the tool offsets 1-99 that `Txxyy` selects by
    /// `yy`, their nose radius and tip only.
    pub tools: ToolTable,
    /// Sinumerik: the cutting edges of the tool data, by tool T and edge D
    /// (`T1 D1`), their radius only; an edge not given has radius 0.
    pub cutting_edges: BTreeMap<(u32, u32), ToolEntry>,
    /// The pause between blocks under G98, where the next block is not
    /// prepared ahead, in ms. It depends on the hardware; the manual gives
    /// no number, so the default is an assumption.
    pub block_pause_ms: u32,
    /// The wait after a stop for the in-position window of machine
    /// constants R06–R07, in ms; the default is an assumption too.
    pub settle_time_ms: u32,
    /// What an M function (besides stops and the tool change) and a tool
    /// change M06 take, in ms: the machine's PLC decides, so none by default.
    pub m_function_ms: u32,
    pub tool_change_ms: u32,
    /// How many blocks the envelope velocity (CNC8x9, machine constant
    /// R338 decade 2) plans ahead, the current one included: the control
    /// looks up to 500 ahead (04 §1.9), so 500 is the default and the most.
    pub look_ahead_blocks: u32,
    /// The CNC8x9 interpolator tick Ts in µs, which the envelope criteria
    /// use. The manual gives only the CNC8x6's 10 ms; 2 ms is an assumption:
    /// the CNC8x9's shortest G24 block, and the tick at which the manual's
    /// R385 example (10000 mm/s²) takes over from the accuracy criterion
    /// at about 20 µm, as it says R385 does when R384 is off or 50 µm.
    pub envelope_tick_us: u32,
    /// Haas lathe: the ramps of working feed and of rapid traverse in
    /// mm/s², and how fast the spindle changes its speed in rpm/s; `None`
    /// takes what the control's velocity policy assumes. A CNC8x6 reads
    /// its ramps from machine constants R52, R236 and R237.
    pub feed_acceleration: Option<u32>,
    pub rapid_acceleration: Option<u32>,
    pub spindle_acceleration: Option<u32>,
    /// Haas lathe: Setting 85, the largest corner rounding in µm, which
    /// G187 without P or E restores; `None` takes the policy's assumption.
    pub corner_rounding_um: Option<u32>,
}

/// How far an axis may travel, in thousandths (µm, or thousandths of a
/// degree) from the machine zero; `None` where it is not limited.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct TravelLimits {
    pub min: Option<i32>,
    pub max: Option<i32>,
}

impl TravelLimits {
    /// The limit a position (mm, or degrees) lies beyond, in its unit;
    /// `None` within them.
    pub fn passed_by(&self, position: f64) -> Option<f64> {
        let limit = |limit: Option<i32>| limit.map(|limit| f64::from(limit) / 1000.0);
        limit(self.min).filter(|&min| position < min).or(limit(self.max).filter(|&max| position > max))
    }
}

impl Default for MachineConfig {
    fn default() -> Self {
        MachineConfig {
            control: Dialect::default(),
            axes: b"XYZUVC".to_vec(),
            feed_limit: 24_000,
            rapid_rate: 10_000,
            rapid_rates: BTreeMap::new(),
            limits: BTreeMap::new(),
            diameter_axis: None,
            constants: BTreeMap::new(),
            cycle_file: None,
            offsets: OffsetTable::default(),
            tools: ToolTable::default(),
            cutting_edges: BTreeMap::new(),
            block_pause_ms: 20,
            settle_time_ms: 10,
            m_function_ms: 0,
            tool_change_ms: 0,
            look_ahead_blocks: 500,
            envelope_tick_us: 2000,
            feed_acceleration: None,
            rapid_acceleration: None,
            spindle_acceleration: None,
            corner_rounding_um: None,
        }
    }
}

impl MachineConfig {
    /// The machine a program for `control` runs on when the configuration
    /// describes none: for CNC8x6 the default, a machine with axes XYZUVC;
    /// for the Haas lathe a two-axis lathe, X (a diameter) and Z; for
    /// Sinumerik a three-axis mill, XYZ (an assumption: the seed names no
    /// machine, and a mill is what its listings program).
    pub fn of_control(control: Dialect) -> MachineConfig {
        match control {
            Dialect::Cnc8x6 => MachineConfig::default(),
            Dialect::HaasLathe => {
                MachineConfig { control, axes: b"XZ".to_vec(), diameter_axis: Some(b'X'), ..MachineConfig::default() }
            }
            Dialect::Sinumerik => MachineConfig { control, axes: b"XYZ".to_vec(), ..MachineConfig::default() },
        }
    }

    /// The axes a run's steps keep, in their order: axes 1–6.
    pub fn step_axes(&self) -> &[u8] {
        &self.axes[..self.axes.len().min(crate::axes::MAX_AXES)]
    }

    /// A machine constant's raw value: configured, else the catalogue's
    /// default, else zero.
    pub fn constant(&self, number: u32) -> i64 {
        self.known_constant(number).unwrap_or(0)
    }

    /// A machine constant's raw value when the configuration or the
    /// catalogue gives one; `None` for a constant without a documented
    /// default that the configuration does not set.
    pub fn known_constant(&self, number: u32) -> Option<i64> {
        self.constants.get(&number).copied().or_else(|| self.default_constant(number))
    }

    /// A machine constant's documented default, from the control's
    /// catalogue.
    pub fn default_constant(&self, number: u32) -> Option<i64> {
        self.control.catalogue().machine_constant(number).and_then(|c| c.default.as_deref()).and_then(parse_constant)
    }

    /// Decade `decade` (1 = rightmost digit) of a machine constant.
    pub fn decade(&self, number: u32, decade: u32) -> u8 {
        self.known_decade(number, decade).unwrap_or(0)
    }

    /// Decade `decade` of a machine constant the configuration or the
    /// catalogue gives.
    pub fn known_decade(&self, number: u32, decade: u32) -> Option<u8> {
        let raw = self.known_constant(number)?.unsigned_abs();
        // Decades beyond the number's digits are zero.
        Some(10u64.checked_pow(decade.saturating_sub(1)).map_or(0, |divisor| (raw / divisor % 10) as u8))
    }

    /// Whether parameter arithmetic reads fields 50–99 as double-precision
    /// pairs: machine constant 283 decade 4, and when that is 2, decade 1
    /// of R95 (`r95`, raw) as the arithmetic starts (`None`: not known).
    pub fn double_precision(&self, r95: Option<i64>) -> Option<bool> {
        match self.decade(283, 4) {
            0 => Some(true),
            1 => Some(false),
            2 => r95.map(|r95| r95.rem_euclid(10) == 0),
            _ => None,
        }
    }

    /// The rapid traverse of the axis `letter` in mm/min (degrees/min).
    pub fn axis_rapid_rate(&self, letter: u8) -> u32 {
        self.rapid_rates.get(&letter).copied().unwrap_or(self.rapid_rate)
    }

    /// How far an arc's end point may lie from its circle, in mm: machine
    /// constant 55 in µm, at least the 1 µm the control computes in (01
    /// §6.4).
    pub fn arc_tolerance(&self) -> f64 {
        self.constant(55).max(1) as f64 / 1000.0
    }

    /// Whether `letter` names a configured axis.
    pub fn is_axis(&self, letter: u8) -> bool {
        self.axes.contains(&letter.to_ascii_uppercase())
    }
}

/// Reads a machine-constant value as written in TAB0.REK: with a decimal
/// point in thousandths (`60.000`), without one as the raw decades.
pub fn parse_constant(text: &str) -> Option<i64> {
    let value = signed_decimal(text.trim())?;
    let scale = if value.has_point() { 3 } else { 0 };
    i64::try_from(value.scaled(scale)?).ok()
}

/// The zero-offset table: per row the offset of each axis from the
/// machine zero (CNC8x6: G53-G59, 01 §5.5; Haas lathe: G54-G59 and
/// G110-G129). Rows the configuration does not give are zero.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct OffsetTable {
    /// Offsets by G code, per axis 1-6, in thousandths (of a diameter on a
    /// Haas lathe's X).
    pub rows: BTreeMap<u8, [i32; 6]>,
}

impl OffsetTable {
    /// The offsets of `G<code>`, per axis.
    pub fn offset(&self, code: u8) -> [i32; 6] {
        self.rows.get(&code).copied().unwrap_or_default()
    }
}

/// One entry of the correction table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct ToolEntry {
    /// The radius correction `R`, in µm.
    pub radius: i32,
    /// Length corrections of axes 1-6, in thousandths.
    pub lengths: [i32; 6],
    /// The position of a lathe tool's tip relative to its nose radius
    /// centre: CNC8x6 `P`, 1-9 (000:2243-2251); Haas lathe, the tip code
    /// 0-9 (lathe manual §7.1 (001:879-951)). `None` when not given, which
    /// the controls take as the centre itself (000:2586-2590).
    pub tip: Option<u8>,
}

/// The correction table: entries D1-D99 (02 §1.2), or a Haas lathe's tool
/// offsets 1-99. Entries the configuration does not give are zero.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct ToolTable {
    pub entries: BTreeMap<u8, ToolEntry>,
}

impl ToolTable {
    /// Entry `D<number>` (Haas lathe: offset `number`).
    pub fn entry(&self, number: u8) -> ToolEntry {
        self.entries.get(&number).copied().unwrap_or_default()
    }
}

/// A number as machine files write it: an optional sign,
/// digits and an optional decimal point.
pub(crate) fn signed_decimal(text: &str) -> Option<Decimal> {
    match text.as_bytes().first() {
        Some(b'-') => Decimal::parse(Some(Sign::Minus), &text[1..]),
        Some(b'+') => Decimal::parse(Some(Sign::Plus), &text[1..]),
        _ => Decimal::parse(None, text),
    }
}
