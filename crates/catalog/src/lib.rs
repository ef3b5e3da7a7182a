//! The language catalogue: every code, address, parameter, machine constant,
//! arithmetic operation and fixed cycle of a dialect, described once, as data.
//!
//! The parser reads the address table (which letter starts a block, which
//! one is the parameter letter), and the checker, hover, completion, the
//! executor and `ncc explain` read the rest. The data lives in TOML files
//! under `data/<dialect>/`, compiled into the binary and parsed once on first
//! use; tests validate them against the manual's tables.

mod dialect_id;
mod explain;
mod render;
pub mod schema;

use std::{collections::HashMap, ops::RangeInclusive, sync::OnceLock};

pub use crate::{
    dialect_id::{UnknownDialect, is_control_file, macrocycle_number, program_file_number},
    explain::{Item, NotFound},
    schema::*,
};

/// The programming language of a control. Matches on it are exhaustive on
/// purpose: adding a dialect makes the compiler list every place to extend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Dialect {
    /// MEFI CNC836 / CNC846 / CNC856.
    #[default]
    Cnc8x6,
    /// Haas lathe, classic control (Fanuc-style ISO).
    HaasLathe,
    /// Siemens Sinumerik.
    Sinumerik,
}

impl Dialect {
    /// The catalogue of this dialect.
    pub fn catalogue(self) -> &'static Catalogue {
        match self {
            Dialect::Cnc8x6 => {
                static CNC8X6: OnceLock<Catalogue> = OnceLock::new();
                CNC8X6.get_or_init(|| Catalogue::load(&CNC8X6_FILES))
            }
            Dialect::HaasLathe => {
                static HAAS_LATHE: OnceLock<Catalogue> = OnceLock::new();
                HAAS_LATHE.get_or_init(|| Catalogue::load(&HAAS_LATHE_FILES))
            }
            Dialect::Sinumerik => {
                static SINUMERIK: OnceLock<Catalogue> = OnceLock::new();
                SINUMERIK.get_or_init(|| Catalogue::load(&SINUMERIK_FILES))
            }
        }
    }
}

/// The data files of one dialect, by name and content.
struct DataFiles {
    codes: (&'static str, &'static str),
    addresses: (&'static str, &'static str),
    parameters: (&'static str, &'static str),
    machine_constants: (&'static str, &'static str),
    operations: (&'static str, &'static str),
    cycles: (&'static str, &'static str),
    /// The language's keywords, functions and system variables, for
    /// dialects with a language beyond addresses and codes (Sinumerik).
    language: Option<LanguageFiles>,
}

struct LanguageFiles {
    keywords: (&'static str, &'static str),
    functions: (&'static str, &'static str),
    system_variables: (&'static str, &'static str),
}

macro_rules! data_file {
    ($dialect:literal, $name:literal) => {
        ($name, include_str!(concat!("../data/", $dialect, "/", $name)))
    };
}

static CNC8X6_FILES: DataFiles = DataFiles {
    codes: data_file!("cnc8x6", "codes.toml"),
    addresses: data_file!("cnc8x6", "addresses.toml"),
    parameters: data_file!("cnc8x6", "parameters.toml"),
    machine_constants: data_file!("cnc8x6", "machine_constants.toml"),
    operations: data_file!("cnc8x6", "operations.toml"),
    cycles: data_file!("cnc8x6", "cycles.toml"),
    language: None,
};

static HAAS_LATHE_FILES: DataFiles = DataFiles {
    codes: data_file!("haas-lathe", "codes.toml"),
    addresses: data_file!("haas-lathe", "addresses.toml"),
    parameters: data_file!("haas-lathe", "parameters.toml"),
    machine_constants: data_file!("haas-lathe", "machine_constants.toml"),
    operations: data_file!("haas-lathe", "operations.toml"),
    cycles: data_file!("haas-lathe", "cycles.toml"),
    language: None,
};

static SINUMERIK_FILES: DataFiles = DataFiles {
    codes: data_file!("sinumerik", "codes.toml"),
    addresses: data_file!("sinumerik", "addresses.toml"),
    parameters: data_file!("sinumerik", "parameters.toml"),
    machine_constants: data_file!("sinumerik", "machine_constants.toml"),
    operations: data_file!("sinumerik", "operations.toml"),
    cycles: data_file!("sinumerik", "cycles.toml"),
    language: Some(LanguageFiles {
        keywords: data_file!("sinumerik", "keywords.toml"),
        functions: data_file!("sinumerik", "functions.toml"),
        system_variables: data_file!("sinumerik", "system_variables.toml"),
    }),
};

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CodesFile {
    #[serde(rename = "group")]
    groups: Vec<Group>,
    #[serde(rename = "code")]
    codes: Vec<Code>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AddressesFile {
    #[serde(rename = "address")]
    addresses: Vec<Address>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ParametersFile {
    parameters: ParameterOverview,
    #[serde(default, rename = "range")]
    ranges: Vec<ParameterRange>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineConstantsFile {
    #[serde(default)]
    terms: ConstantTerms,
    #[serde(rename = "constant")]
    constants: Vec<MachineConstant>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct OperationsFile {
    #[serde(rename = "operation")]
    operations: Vec<Operation>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CyclesFile {
    #[serde(rename = "cycle")]
    cycles: Vec<Cycle>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct KeywordsFile {
    #[serde(rename = "keyword")]
    keywords: Vec<Keyword>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FunctionsFile {
    #[serde(rename = "function")]
    functions: Vec<Function>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SystemVariablesFile {
    #[serde(rename = "prefix")]
    prefixes: Vec<VariablePrefix>,
    #[serde(rename = "variable")]
    variables: Vec<SystemVariable>,
}

fn parse<T: serde::de::DeserializeOwned>((name, text): (&str, &str)) -> T {
    // The files are part of the program and checked by the tests; a broken
    // one is a build defect, never a user error.
    toml::from_str(text).unwrap_or_else(|error| panic!("catalogue file {name}: {error}"))
}

/// Everything known about a dialect's language.
#[derive(Debug)]
pub struct Catalogue {
    pub groups: Vec<Group>,
    pub codes: Vec<Code>,
    pub addresses: Vec<Address>,
    pub parameters: ParameterOverview,
    pub parameter_ranges: Vec<ParameterRange>,
    pub machine_constants: Vec<MachineConstant>,
    pub constant_terms: ConstantTerms,
    pub operations: Vec<Operation>,
    pub cycles: Vec<Cycle>,
    pub keywords: Vec<Keyword>,
    pub functions: Vec<Function>,
    pub system_variables: Vec<SystemVariable>,
    /// Longest first, so that `$AA_` is tried before `$A_`.
    pub variable_prefixes: Vec<VariablePrefix>,
    codes_by_number: HashMap<(char, u32), usize>,
    /// The codes written as words, by their upper-case spelling.
    codes_by_word: HashMap<String, usize>,
    roles: [Option<AddressRole>; 128],
    /// The index in `addresses` of each address byte, either case.
    address_index: [Option<u8>; 128],
    /// [`Catalogue::modal_group_index`] of the codes below [`DENSE_CODES`]
    /// of each function letter, which every block asks for.
    modal_groups: Vec<(char, [Option<u8>; DENSE_CODES as usize])>,
    /// The code ranges whose unlisted codes belong to a group, with the
    /// group's index.
    unlisted_ranges: Vec<(RangeInclusive<(char, u32)>, usize)>,
}

/// Code numbers looked up in a table rather than a map.
const DENSE_CODES: u32 = 128;

impl Catalogue {
    fn load(files: &DataFiles) -> Catalogue {
        let codes: CodesFile = parse(files.codes);
        let mut addresses: AddressesFile = parse(files.addresses);
        for address in &mut addresses.addresses {
            let number = |text: &Option<String>| text.as_deref().and_then(|t| t.parse::<f64>().ok());
            address.bounds = number(&address.min).zip(number(&address.max));
        }
        let parameters: ParametersFile = parse(files.parameters);
        let constants: MachineConstantsFile = parse(files.machine_constants);
        let operations: OperationsFile = parse(files.operations);
        let cycles: CyclesFile = parse(files.cycles);
        let (keywords, functions, system_variables) = match &files.language {
            Some(language) => {
                let keywords: KeywordsFile = parse(language.keywords);
                let functions: FunctionsFile = parse(language.functions);
                let variables: SystemVariablesFile = parse(language.system_variables);
                (keywords.keywords, functions.functions, variables)
            }
            None => (Vec::new(), Vec::new(), SystemVariablesFile { prefixes: Vec::new(), variables: Vec::new() }),
        };
        let mut variable_prefixes = system_variables.prefixes;
        variable_prefixes.sort_by_key(|prefix| std::cmp::Reverse(prefix.prefix.len()));

        let codes_by_number =
            codes.codes.iter().enumerate().filter_map(|(i, code)| Some((split_code(&code.code)?, i))).collect();
        let codes_by_word = codes
            .codes
            .iter()
            .enumerate()
            .filter(|(_, code)| code.is_word())
            .map(|(i, code)| (code.code.to_ascii_uppercase(), i))
            .collect();
        let mut roles = [None; 128];
        let mut address_index = [None; 128];
        // Only one-character addresses: the bytes of `CR` are no addresses.
        for (index, address) in addresses.addresses.iter().enumerate().filter(|(_, a)| a.letter.len() == 1) {
            for byte in address.letter.bytes().filter(u8::is_ascii) {
                for case in [byte.to_ascii_uppercase(), byte.to_ascii_lowercase()] {
                    roles[usize::from(case)] = Some(address.role);
                    address_index[usize::from(case)] = u8::try_from(index).ok();
                }
            }
        }
        let unlisted_ranges = codes
            .groups
            .iter()
            .enumerate()
            .filter_map(|(index, group)| {
                let [first, last] = group.takes_unlisted.as_ref()?;
                Some((split_code(first)?..=split_code(last)?, index))
            })
            .collect();
        let mut catalogue = Catalogue {
            groups: codes.groups,
            codes: codes.codes,
            addresses: addresses.addresses,
            parameters: parameters.parameters,
            parameter_ranges: parameters.ranges,
            machine_constants: constants.constants,
            constant_terms: constants.terms,
            operations: operations.operations,
            cycles: cycles.cycles,
            keywords,
            functions,
            system_variables: system_variables.variables,
            variable_prefixes,
            codes_by_number,
            codes_by_word,
            roles,
            address_index,
            modal_groups: Vec::new(),
            unlisted_ranges,
        };
        let letters: Vec<char> = catalogue.function_letters().map(char::from).collect();
        for letter in letters {
            let mut table = [None; DENSE_CODES as usize];
            for (number, group) in (0..DENSE_CODES).zip(&mut table) {
                *group = catalogue.find_modal_group(letter, number).and_then(|index| u8::try_from(index).ok());
            }
            catalogue.modal_groups.push((letter, table));
        }
        catalogue
    }

    /// The (upper-case) letters of the codes, in catalogue order.
    pub fn function_letters(&self) -> impl Iterator<Item = u8> + '_ {
        self.addresses.iter().filter(|a| a.role == AddressRole::Function).filter_map(|a| a.letter.bytes().next())
    }

    /// The letter of the preparatory functions (G).
    pub fn preparatory_letter(&self) -> Option<u8> {
        let address = self.addresses.iter().find(|a| a.function == Some(FunctionKind::Preparatory))?;
        address.letter.bytes().next()
    }

    /// The index in [`Catalogue::groups`] of the group a code puts itself in
    /// force in: `None` for block-only codes and codes outside the groups.
    pub fn modal_group_index(&self, letter: char, number: u32) -> Option<usize> {
        let upper = letter.to_ascii_uppercase();
        let table = self.modal_groups.iter().find(|(function, _)| *function == upper);
        match table.and_then(|(_, table)| table.get(number as usize)) {
            Some(index) => index.map(usize::from),
            None => self.find_modal_group(letter, number),
        }
    }

    fn find_modal_group(&self, letter: char, number: u32) -> Option<usize> {
        if self.code(letter, number).is_some_and(|code| code.modality != Modality::Modal) {
            return None;
        }
        let group = self.group_of(letter, number)?;
        self.groups.iter().position(|g| std::ptr::eq(g, group))
    }

    /// The code `letter` + `number` (`'G', 1` is G01), if the catalogue lists it.
    pub fn code(&self, letter: char, number: u32) -> Option<&Code> {
        self.codes_by_number.get(&(letter.to_ascii_uppercase(), number)).map(|&i| &self.codes[i])
    }

    /// The code written as the word `word` (`BSPLINE`), any case.
    pub fn word_code(&self, word: &str) -> Option<&Code> {
        self.codes_by_word.get(&word.to_ascii_uppercase()).map(|&i| &self.codes[i])
    }

    /// The code `name` however it is written: `G01`, `G1`, `BSPLINE`.
    pub fn code_named(&self, name: &str) -> Option<&Code> {
        match split_code(name) {
            Some((letter, number)) => self.code(letter, number),
            None => self.word_code(name),
        }
    }

    /// The index in [`Catalogue::groups`] of the group a code written as a
    /// word puts itself in force in, like [`Catalogue::modal_group_index`].
    pub fn word_modal_group_index(&self, word: &str) -> Option<usize> {
        let code = self.word_code(word).filter(|code| code.modality == Modality::Modal)?;
        let id = code.group.as_deref()?;
        self.groups.iter().position(|group| group.id == id)
    }

    /// The code of `group` with number `index` inside it: what Sinumerik's
    /// `G[1]=2` selects (G1).
    pub fn code_at(&self, group: &str, index: u32) -> Option<&Code> {
        self.codes.iter().find(|code| code.group.as_deref() == Some(group) && code.index == Some(index))
    }

    pub fn group(&self, id: &str) -> Option<&Group> {
        self.groups.iter().find(|g| g.id.eq_ignore_ascii_case(id))
    }

    /// The group of a code: its listed group, or the group that takes the
    /// unlisted codes of a range the code is in (`takes_unlisted`).
    pub fn group_of(&self, letter: char, number: u32) -> Option<&Group> {
        match self.code(letter, number) {
            Some(code) => self.group(code.group.as_deref()?),
            None => {
                let code = (letter.to_ascii_uppercase(), number);
                let (_, index) = self.unlisted_ranges.iter().find(|(range, _)| range.contains(&code))?;
                self.groups.get(*index)
            }
        }
    }

    /// The codes of a group, in catalogue order.
    pub fn codes_in<'a>(&'a self, group: &'a str) -> impl Iterator<Item = &'a Code> + 'a {
        self.codes.iter().filter(move |c| c.group.as_deref() == Some(group))
    }

    pub fn address(&self, letter: &str) -> Option<&Address> {
        self.addresses.iter().find(|a| a.letter.eq_ignore_ascii_case(letter))
    }

    /// The address of a byte, case-insensitively; a table lookup, for the
    /// executor's every word.
    pub fn address_of(&self, byte: u8) -> Option<&Address> {
        let index = self.address_index.get(usize::from(byte)).copied().flatten()?;
        self.addresses.get(usize::from(index))
    }

    /// The role of an address byte, case-insensitively; a table lookup, for
    /// the parser's hot loop.
    pub fn role_of(&self, byte: u8) -> Option<AddressRole> {
        self.roles.get(usize::from(byte)).copied().flatten()
    }

    /// The (upper-case) letter that has `role`, e.g. `N` for block numbers.
    pub fn letter_with_role(&self, role: AddressRole) -> Option<u8> {
        self.addresses.iter().find(|a| a.role == role).map(|a| a.letter.as_bytes()[0])
    }

    /// The machine constant `number` (an entry may describe a run of them).
    pub fn machine_constant(&self, number: u32) -> Option<&MachineConstant> {
        self.machine_constants.iter().find(|c| (c.number..=c.last.unwrap_or(c.number)).contains(&number))
    }

    /// Whether `number` is a program parameter (`R0`–`R95`).
    pub fn is_parameter(&self, number: u32) -> bool {
        number < self.parameters.count
    }

    /// The ranges with a special role that contain parameter `number`.
    pub fn parameter_ranges_of(&self, number: u32) -> impl Iterator<Item = &ParameterRange> {
        self.parameter_ranges.iter().filter(move |r| (r.first..=r.last).contains(&number))
    }

    pub fn operation(&self, code: u32) -> Option<&Operation> {
        self.operations.iter().find(|op| op.code == code)
    }

    pub fn keyword(&self, word: &str) -> Option<&Keyword> {
        self.keywords.iter().find(|k| k.word.eq_ignore_ascii_case(word))
    }

    pub fn function(&self, name: &str) -> Option<&Function> {
        self.functions.iter().find(|f| f.name.eq_ignore_ascii_case(name))
    }

    /// What the catalogue knows of the system variable `name` (`$P_GG`,
    /// `$P_GG[6]`, `$MC_MM_NUM_R_PARAM`); `None` when no known prefix starts it.
    pub fn system_variable(&self, name: &str) -> Option<SystemVariableInfo<'_>> {
        let name = name.split('[').next().unwrap_or_default().trim();
        if let Some(variable) = self.system_variables.iter().find(|v| v.name.eq_ignore_ascii_case(name)) {
            return Some(SystemVariableInfo::Documented(variable));
        }
        let upper = name.to_ascii_uppercase();
        let prefix = self.variable_prefixes.iter().find(|p| upper.starts_with(&p.prefix.to_ascii_uppercase()))?;
        let rest = &upper[prefix.prefix.len()..];
        let constant = prefix
            .machine_data
            .then(|| {
                self.machine_constants.iter().find(|c| c.name.as_deref().is_some_and(|n| n.eq_ignore_ascii_case(rest)))
            })
            .flatten();
        Some(match constant {
            Some(constant) => SystemVariableInfo::MachineData { prefix, constant },
            None => SystemVariableInfo::Undocumented { prefix },
        })
    }

    /// The fixed cycles with this code (one per flavour).
    pub fn cycles_for(&self, code: &str) -> impl Iterator<Item = &Cycle> + use<'_> {
        let code = code.to_ascii_uppercase();
        self.cycles.iter().filter(move |c| c.code.eq_ignore_ascii_case(&code))
    }

    /// The hole cycle with this code: one that says what it does to the
    /// hole at the current position (`hole`).
    pub fn hole_cycle(&self, code: &str) -> Option<&Cycle> {
        self.cycles_for(code).find(|cycle| cycle.hole.is_some())
    }
}

/// What the catalogue knows of a system variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SystemVariableInfo<'a> {
    Documented(&'a SystemVariable),
    /// Machine data the catalogue describes, read through its prefix.
    MachineData {
        prefix: &'a VariablePrefix,
        constant: &'a MachineConstant,
    },
    /// A name with a known prefix that the catalogue does not list: a system
    /// variable ncc does not document, never an error.
    Undocumented {
        prefix: &'a VariablePrefix,
    },
}

/// `"G01"` → `('G', 1)`.
pub fn split_code(code: &str) -> Option<(char, u32)> {
    let mut chars = code.chars();
    let letter = chars.next()?.to_ascii_uppercase();
    let digits = chars.as_str();
    if !letter.is_ascii_alphabetic() || digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((letter, digits.parse().ok()?))
}

#[cfg(test)]
mod data_files {
    //! One test per data file and dialect, so that each file can be checked
    //! on its own.

    use super::*;

    fn read(dialect: &str, name: &str) -> (&'static str, &'static str) {
        let path = format!("{}/data/{dialect}/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        (Box::leak(format!("{dialect}/{name}").into_boxed_str()), Box::leak(text.into_boxed_str()))
    }

    const DIALECTS: [&str; 3] = ["cnc8x6", "haas-lathe", "sinumerik"];

    #[test]
    fn codes() {
        for dialect in DIALECTS {
            let file: CodesFile = parse(read(dialect, "codes.toml"));
            assert!(!file.codes.is_empty() && !file.groups.is_empty(), "{dialect}");
        }
    }

    #[test]
    fn addresses() {
        for dialect in DIALECTS {
            let file: AddressesFile = parse(read(dialect, "addresses.toml"));
            assert!(!file.addresses.is_empty(), "{dialect}");
        }
    }

    #[test]
    fn parameters() {
        let file: ParametersFile = parse(read("cnc8x6", "parameters.toml"));
        assert_eq!(file.parameters.count, 96);
        let file: ParametersFile = parse(read("haas-lathe", "parameters.toml"));
        assert!(file.ranges.iter().all(|range| range.last < file.parameters.count));
    }

    #[test]
    fn machine_constants() {
        for dialect in DIALECTS {
            let file: MachineConstantsFile = parse(read(dialect, "machine_constants.toml"));
            assert!(!file.constants.is_empty(), "{dialect}");
        }
    }

    #[test]
    fn operations() {
        let file: OperationsFile = parse(read("cnc8x6", "operations.toml"));
        assert_eq!(file.operations.len(), 52);
        let file: OperationsFile = parse(read("haas-lathe", "operations.toml"));
        assert!(file.operations.iter().all(|op| op.symbol.is_some()));
    }

    #[test]
    fn language() {
        let file: KeywordsFile = parse(read("sinumerik", "keywords.toml"));
        assert!(!file.keywords.is_empty());
        let file: FunctionsFile = parse(read("sinumerik", "functions.toml"));
        assert!(!file.functions.is_empty());
        let file: SystemVariablesFile = parse(read("sinumerik", "system_variables.toml"));
        assert!(!file.prefixes.is_empty() && !file.variables.is_empty());
    }

    #[test]
    fn cycles() {
        for dialect in DIALECTS {
            let file: CyclesFile = parse(read(dialect, "cycles.toml"));
            assert!(!file.cycles.is_empty(), "{dialect}");
        }
    }
}

#[cfg(test)]
mod tests;
