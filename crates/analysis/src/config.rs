//! The project configuration, `ncc.toml`: rule severities and the machine.
//!
//! ```toml
//! [rules]
//! missing-feed = "warning"     # by name or by code
//! S009 = "off"
//! non-canonical-word-order = "info"   # opt-in rules are off until named
//!
//! [machine]
//! axes = ["X", "Y", "Z", "U", "V", "C"]   # letters of axes 1-6
//! feed-limit = 24000                      # mm/min
//! rapid-rate = 10000                      # mm/min, every axis (G00)
//! cycle-file = "PCYKLYDG.NCP"             # CNC836.KNF $17: what G81-G89 do
//!
//! [machine.constants]                      # as in TAB0.REK
//! R339 = "01000000"                        # the eight decades
//! R39 = "60.000"                           # or with the decimal point
//! ```

use std::{
    collections::BTreeMap,
    path::{Path, PathBuf},
};

pub use nc_exec::machine::{MachineConfig, parse_constant};
use ncc_syntax::Severity;
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
    /// Severity overrides by rule code or name.
    pub rules: BTreeMap<String, Level>,
    pub machine: MachineConfig,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct ConfigFile {
    #[serde(default)]
    rules: BTreeMap<String, Level>,
    #[serde(default)]
    machine: Option<MachineFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct MachineFile {
    axes: Option<Vec<String>>,
    feed_limit: Option<u32>,
    rapid_rate: Option<u32>,
    cycle_file: Option<String>,
    #[serde(default)]
    constants: BTreeMap<String, String>,
}

impl Config {
    /// Reads a configuration file's text; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Config, String> {
        let file: ConfigFile = toml::from_str(text).map_err(|e| format!("{origin}: {e}"))?;
        let mut config = Config { rules: file.rules, machine: MachineConfig::default() };
        if let Some(unknown) = config.rules.keys().find(|key| crate::Rule::find(key).is_none()) {
            return Err(format!("{origin}: [rules] names no rule `{unknown}` (see `ncc rules`)"));
        }
        if let Some(machine) = file.machine {
            if let Some(axes) = machine.axes {
                let letters: Vec<u8> =
                    axes.iter().map(|a| a.as_bytes().first().copied().unwrap_or(b'?').to_ascii_uppercase()).collect();
                if axes.iter().any(|a| a.len() != 1 || !a.as_bytes()[0].is_ascii_alphabetic())
                    || axes.is_empty()
                    || axes.len() > 6
                {
                    return Err(format!("{origin}: machine.axes must list one to six axis letters"));
                }
                config.machine.axes = letters;
            }
            if let Some(limit) = machine.feed_limit {
                config.machine.feed_limit = limit;
            }
            if let Some(rate) = machine.rapid_rate {
                if rate == 0 {
                    return Err(format!("{origin}: machine.rapid-rate must be above 0 mm/min"));
                }
                config.machine.rapid_rate = rate;
            }
            if let Some(name) = machine.cycle_file {
                if name.trim().is_empty() {
                    return Err(format!("{origin}: machine.cycle-file must name a file, e.g. \"PCYKLYDG.NCP\""));
                }
                config.machine.cycle_file = Some(name);
            }
            for (name, value) in machine.constants {
                let number = name
                    .strip_prefix(['R', 'r'])
                    .and_then(|n| n.parse().ok())
                    .ok_or_else(|| format!("{origin}: machine.constants key `{name}` is not like `R339`"))?;
                let raw = parse_constant(&value)
                    .ok_or_else(|| format!("{origin}: machine constant {name} = `{value}` is not a number"))?;
                config.machine.constants.insert(number, raw);
            }
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
        let level = self.rules.get(diagnostic.code).or_else(|| self.rules.get(diagnostic.name));
        match level {
            None if crate::Rule::find(diagnostic.code).is_some_and(|rule| rule.opt_in) => None,
            None => Some(diagnostic),
            Some(level) => {
                diagnostic.severity = level.severity()?;
                Some(diagnostic)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rules_and_machine() {
        let config = Config::from_toml(
            "[rules]\nS009 = \"off\"\nunknown-code = \"warning\"\n[machine]\naxes = [\"X\", \"Z\"]\nfeed-limit = 10000\nrapid-rate = 15000\n[machine.constants]\nR339 = \"01000000\"\nR39 = \"45.5\"\n",
            "ncc.toml",
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
        let error = Config::from_toml("[rules]\nno-such-rule = \"off\"\n", "ncc.toml").unwrap_err();
        assert!(error.contains("no-such-rule"), "{error}");
        let error = Config::from_toml("[machine]\naxes = [\"XY\"]\n", "ncc.toml").unwrap_err();
        assert!(error.contains("axis letters"), "{error}");
        assert!(Config::from_toml("[machine.constants]\nR39 = \"abc\"\n", "x").is_err());
        assert!(Config::from_toml("[unknown]\n", "x").is_err());
        let error = Config::from_toml("[machine]\nrapid-rate = 0\n", "x").unwrap_err();
        assert!(error.contains("rapid-rate"), "{error}");
    }

    #[test]
    fn defaults_come_from_the_catalogue() {
        let machine = MachineConfig::default();
        assert_eq!(machine.constant(39), 60_000, "R39 default 60.000");
        assert_eq!(machine.constant(339), 0);
    }
}
