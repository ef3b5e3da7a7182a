//! The controls ncc knows by name, and which files are whose by default.
//!
//! One contract for the command line (`--dialect`), `ncc.toml` (`dialect`,
//! `[extensions]`) and the language server: a program's dialect is the one
//! named for it, else the one its extension maps to.

use std::{fmt, path::Path, str::FromStr};

use crate::Dialect;

/// A control language by its name, whether or not this build reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DialectId {
    /// MEFI CNC836 / CNC846 / CNC856.
    Cnc8x6,
    /// A Haas lathe, classic control (Fanuc-style ISO).
    HaasLathe,
    /// Siemens Sinumerik.
    Sinumerik,
}

impl DialectId {
    pub const ALL: [DialectId; 3] = [DialectId::Cnc8x6, DialectId::HaasLathe, DialectId::Sinumerik];

    /// The name users write.
    pub fn name(self) -> &'static str {
        match self {
            DialectId::Cnc8x6 => "cnc8x6",
            DialectId::HaasLathe => "haas-lathe",
            DialectId::Sinumerik => "sinumerik",
        }
    }

    /// The control's name as people know it.
    pub fn title(self) -> &'static str {
        match self {
            DialectId::Cnc8x6 => "CNC8x6",
            DialectId::HaasLathe => "Haas lathe",
            DialectId::Sinumerik => "Siemens Sinumerik",
        }
    }

    /// The dialect's implementation, when this build has one.
    pub fn implementation(self) -> Option<Dialect> {
        match self {
            DialectId::Cnc8x6 => Some(Dialect::Cnc8x6),
            DialectId::HaasLathe => Some(Dialect::HaasLathe),
            DialectId::Sinumerik => Some(Dialect::Sinumerik),
        }
    }

    /// The file extensions of the dialect's programs, by default.
    pub fn default_extensions(self) -> &'static [&'static str] {
        match self {
            DialectId::Cnc8x6 => &["NCP"],
            DialectId::HaasLathe => &["nc", "tap"],
            DialectId::Sinumerik => &["MPF", "SPF"],
        }
    }

    /// The dialect a file's name gives by default: its extension (any case),
    /// a CNC8x6 macrocycle file name `L<number>`, or a Haas program file
    /// `O<number>` without an extension, as the control stores programs.
    pub fn by_default_for(path: &Path) -> Option<DialectId> {
        let by_extension = path.extension().and_then(|extension| {
            let extension = extension.to_str()?;
            DialectId::ALL
                .into_iter()
                .find(|dialect| dialect.default_extensions().iter().any(|known| known.eq_ignore_ascii_case(extension)))
        });
        let bare = || path.extension().is_none().then_some(path);
        by_extension
            .or_else(|| macrocycle_number(path).map(|_| DialectId::Cnc8x6))
            .or_else(|| bare().and_then(program_file_number).map(|_| DialectId::HaasLathe))
    }

    /// The message for a program of a dialect this build does not read.
    pub fn not_read(self) -> String {
        format!("ncc does not read {} programs yet (dialect `{}`)", self.title(), self.name())
    }
}

impl From<Dialect> for DialectId {
    fn from(dialect: Dialect) -> DialectId {
        match dialect {
            Dialect::Cnc8x6 => DialectId::Cnc8x6,
            Dialect::HaasLathe => DialectId::HaasLathe,
            Dialect::Sinumerik => DialectId::Sinumerik,
        }
    }
}

impl Dialect {
    /// Every dialect this build reads, in the registry's order: what tests
    /// and benchmarks that hold for every dialect go over.
    pub fn all() -> impl Iterator<Item = Dialect> {
        DialectId::ALL.into_iter().filter_map(DialectId::implementation)
    }
}

impl fmt::Display for DialectId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A dialect name that is none of [`DialectId::ALL`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownDialect(pub String);

impl fmt::Display for UnknownDialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = DialectId::ALL.iter().map(|dialect| dialect.name()).collect();
        write!(f, "unknown dialect `{}` (known: {})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownDialect {}

impl FromStr for DialectId {
    type Err = UnknownDialect;

    fn from_str(name: &str) -> Result<DialectId, UnknownDialect> {
        DialectId::ALL.into_iter().find(|dialect| dialect.name() == name).ok_or_else(|| UnknownDialect(name.to_owned()))
    }
}

impl<'de> serde::Deserialize<'de> for DialectId {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<DialectId, D::Error> {
        let name = String::deserialize(deserializer)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

/// The number of a CNC8x6 macrocycle file `L<number>`, with or without an
/// extension.
pub fn macrocycle_number(path: &Path) -> Option<u32> {
    let stem = path.file_stem()?.to_str()?;
    let digits = stem.strip_prefix(['L', 'l']).filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))?;
    digits.parse().ok()
}

/// The program number a Haas program file's name gives: `O01234` or
/// `O1234.nc` → 1234 (`O` and one to five digits).
pub fn program_file_number(path: &Path) -> Option<u32> {
    let stem = path.file_stem()?.to_str()?;
    let digits =
        stem.strip_prefix('O').filter(|d| (1..=5).contains(&d.len()) && d.bytes().all(|b| b.is_ascii_digit()))?;
    digits.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for dialect in DialectId::ALL {
            assert_eq!(dialect.name().parse(), Ok(dialect));
        }
        assert_eq!(
            "fanuc".parse::<DialectId>().unwrap_err().to_string(),
            "unknown dialect `fanuc` (known: cnc8x6, haas-lathe, sinumerik)"
        );
    }

    #[test]
    fn file_names_give_a_dialect_by_default() {
        let cases = [
            ("a.NCP", Some(DialectId::Cnc8x6)),
            ("b.ncp", Some(DialectId::Cnc8x6)),
            ("L9001", Some(DialectId::Cnc8x6)),
            ("dir/L12.NCP", Some(DialectId::Cnc8x6)),
            ("O1234.nc", Some(DialectId::HaasLathe)),
            ("O1234.NC", Some(DialectId::HaasLathe)),
            ("part.tap", Some(DialectId::HaasLathe)),
            ("O01234", Some(DialectId::HaasLathe)),
            ("dir/O1", Some(DialectId::HaasLathe)),
            ("O123456", None),
            ("Oil", None),
            ("MAIN.MPF", Some(DialectId::Sinumerik)),
            ("cycle.spf", Some(DialectId::Sinumerik)),
            ("README.md", None),
            ("Lx1", None),
            ("NCP", None),
        ];
        for (name, dialect) in cases {
            assert_eq!(DialectId::by_default_for(Path::new(name)), dialect, "{name}");
        }
    }
}
