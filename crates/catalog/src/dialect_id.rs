//! The controls' languages by name, and which files are whose by default.
//!
//! One contract for the command line (`--dialect`), `ncc.toml` (`dialect`,
//! `[extensions]`) and the language server: a program's dialect is the one
//! named for it, else the one its extension maps to.

use std::{fmt, path::Path, str::FromStr};

use crate::Dialect;

impl Dialect {
    /// Every dialect, in the registry's order: what tests and benchmarks
    /// that hold for every dialect go over.
    pub const ALL: [Dialect; 3] = [Dialect::Cnc8x6, Dialect::HaasLathe, Dialect::Sinumerik];

    /// The name users write.
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Cnc8x6 => "cnc8x6",
            Dialect::HaasLathe => "haas-lathe",
            Dialect::Sinumerik => "sinumerik",
        }
    }

    /// The control's name as people know it.
    pub fn title(self) -> &'static str {
        match self {
            Dialect::Cnc8x6 => "CNC8x6",
            Dialect::HaasLathe => "Haas lathe",
            Dialect::Sinumerik => "Siemens Sinumerik",
        }
    }

    /// The file extensions of the dialect's programs, by default.
    pub fn default_extensions(self) -> &'static [&'static str] {
        match self {
            Dialect::Cnc8x6 => &["NCP"],
            Dialect::HaasLathe => &["nc", "tap"],
            Dialect::Sinumerik => &["MPF", "SPF"],
        }
    }

    /// The dialect a file's name gives by default: its extension (any case),
    /// a CNC8x6 macrocycle file name `L<number>`, or a Haas program file
    /// `O<number>` without an extension, as the control stores programs.
    pub fn by_default_for(path: &Path) -> Option<Dialect> {
        let by_extension = path.extension().and_then(|extension| {
            let extension = extension.to_str()?;
            Dialect::ALL
                .into_iter()
                .find(|dialect| dialect.default_extensions().iter().any(|known| known.eq_ignore_ascii_case(extension)))
        });
        let bare = || path.extension().is_none().then_some(path);
        by_extension
            .or_else(|| macrocycle_number(path).map(|_| Dialect::Cnc8x6))
            .or_else(|| bare().and_then(program_file_number).map(|_| Dialect::HaasLathe))
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A dialect name that is none of [`Dialect::ALL`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownDialect(pub String);

impl fmt::Display for UnknownDialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = Dialect::ALL.iter().map(|dialect| dialect.name()).collect();
        write!(f, "unknown dialect `{}` (known: {})", self.0, names.join(", "))
    }
}

impl std::error::Error for UnknownDialect {}

impl FromStr for Dialect {
    type Err = UnknownDialect;

    fn from_str(name: &str) -> Result<Dialect, UnknownDialect> {
        Dialect::ALL.into_iter().find(|dialect| dialect.name() == name).ok_or_else(|| UnknownDialect(name.to_owned()))
    }
}

impl<'de> serde::Deserialize<'de> for Dialect {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Dialect, D::Error> {
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

/// Whether the file at `path` is the one a Sinumerik control names
/// `control_name` (`_N_PROFIL_SPF`): named so, or `PROFIL.SPF`, in any
/// case (004:1452-1454).
pub fn is_control_file(path: &Path, control_name: &str) -> bool {
    let Some(name) = path.file_name().and_then(|name| name.to_str()) else { return false };
    if name.eq_ignore_ascii_case(control_name) {
        return true;
    }
    let inner = control_name.get(3..).filter(|_| control_name.get(..3).is_some_and(|p| p.eq_ignore_ascii_case("_N_")));
    let Some((stem, extension)) = inner.and_then(|inner| inner.rsplit_once('_')) else { return false };
    name.rsplit_once('.').is_some_and(|(file_stem, file_extension)| {
        file_stem.eq_ignore_ascii_case(stem) && file_extension.eq_ignore_ascii_case(extension)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_files_are_found_by_either_name() {
        let file = |name: &str| is_control_file(Path::new(name), "_N_PROFIL_SPF");
        assert!(file("dir/PROFIL.SPF") && file("profil.spf") && file("_N_PROFIL_SPF") && file("x/_n_profil_spf"));
        assert!(!file("PROFIL.MPF") && !file("PROFIL") && !file("XPROFIL.SPF"));
        assert!(is_control_file(Path::new("UGUD.DEF"), "_N_UGUD_DEF"));
        assert!(!is_control_file(Path::new("A.SPF"), "PROFIL"));
    }

    #[test]
    fn names_read_back() {
        for dialect in Dialect::ALL {
            assert_eq!(dialect.name().parse(), Ok(dialect));
        }
        assert_eq!(
            "fanuc".parse::<Dialect>().unwrap_err().to_string(),
            "unknown dialect `fanuc` (known: cnc8x6, haas-lathe, sinumerik)"
        );
    }

    #[test]
    fn file_names_give_a_dialect_by_default() {
        let cases = [
            ("a.NCP", Some(Dialect::Cnc8x6)),
            ("b.ncp", Some(Dialect::Cnc8x6)),
            ("L9001", Some(Dialect::Cnc8x6)),
            ("dir/L12.NCP", Some(Dialect::Cnc8x6)),
            ("O1234.nc", Some(Dialect::HaasLathe)),
            ("O1234.NC", Some(Dialect::HaasLathe)),
            ("part.tap", Some(Dialect::HaasLathe)),
            ("O01234", Some(Dialect::HaasLathe)),
            ("dir/O1", Some(Dialect::HaasLathe)),
            ("O123456", None),
            ("Oil", None),
            ("MAIN.MPF", Some(Dialect::Sinumerik)),
            ("cycle.spf", Some(Dialect::Sinumerik)),
            ("README.md", None),
            ("Lx1", None),
            ("NCP", None),
        ];
        for (name, dialect) in cases {
            assert_eq!(Dialect::by_default_for(Path::new(name)), dialect, "{name}");
        }
    }
}
