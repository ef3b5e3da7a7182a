//! The files a run writes, reads and deletes (WRITE, READ, DELETE,
//! ISFILE; digest §2.8), kept in memory: the run does no I/O, and the
//! trace hands them on ([`crate::trace::Trace::written`]).
//!
//! Paths are the control's, compared in upper case: a full path
//! (`/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF`) or a bare name. A
//! bare name names the file of that name in whichever directory the run
//! wrote it (assumption: the seed's main program tests
//! `ISFILE("_N_GEOMETRIE_VACKA_SPF")` for the file its cycle writes under
//! a full path, 004:4871, 4921).
//!
//! The error codes are the control's (004:4963-5007): 0 done, 1 path not
//! permitted (empty, or with `..`), 3 file not found (DELETE and READ of a
//! file the run has not written), 4 wrong data type (READ's line number
//! or count below 1).

use crate::trace::WrittenFile;

/// The status WRITE, READ and DELETE put into their error variable.
pub(super) const DONE: i64 = 0;
const PATH_NOT_PERMITTED: i64 = 1;
const FILE_NOT_FOUND: i64 = 3;
const WRONG_TYPE: i64 = 4;

/// The files a run wrote, in the order first written.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Files {
    files: Vec<WrittenFile>,
}

/// The last part of a path: the file's name.
fn name_of(path: &str) -> &str {
    path.rsplit('/').next().unwrap_or(path)
}

fn normal(path: &str) -> Result<String, i64> {
    let path = path.trim().to_ascii_uppercase();
    if path.is_empty() || path.split('/').any(|part| part == "..") || path.ends_with('/') {
        return Err(PATH_NOT_PERMITTED);
    }
    Ok(path)
}

impl Files {
    fn find(&self, path: &str) -> Option<usize> {
        let path = normal(path).ok()?;
        let bare = !path.contains('/');
        self.files.iter().position(|file| file.path == path || (bare && name_of(&file.path) == path))
    }

    pub(super) fn exists(&self, path: &str) -> bool {
        self.find(path).is_some()
    }

    /// WRITE: appends `line` to the file, creating it.
    pub(super) fn write(&mut self, path: &str, line: &str) -> i64 {
        let index = match self.find(path) {
            Some(index) => index,
            None => match normal(path) {
                Ok(path) => {
                    self.files.push(WrittenFile { path, text: String::new() });
                    self.files.len() - 1
                }
                Err(code) => return code,
            },
        };
        let text = &mut self.files[index].text;
        text.push_str(line);
        text.push('\n');
        DONE
    }

    /// DELETE.
    pub(super) fn delete(&mut self, path: &str) -> i64 {
        if let Err(code) = normal(path) {
            return code;
        }
        match self.find(path) {
            Some(index) => {
                self.files.remove(index);
                DONE
            }
            None => FILE_NOT_FOUND,
        }
    }

    /// READ: `count` lines from line `first` (from 1), fewer at the end.
    pub(super) fn read(&self, path: &str, first: i64, count: i64) -> Result<Vec<String>, i64> {
        normal(path)?;
        let index = self.find(path).ok_or(FILE_NOT_FOUND)?;
        let (Ok(first), Ok(count)) = (usize::try_from(first - 1), usize::try_from(count)) else {
            return Err(WRONG_TYPE);
        };
        if count == 0 {
            return Err(WRONG_TYPE);
        }
        Ok(self.files[index].text.lines().skip(first).take(count).map(str::to_owned).collect())
    }

    /// The text of the program file named `name` (`_N_GEOMETRIE_VACKA_SPF`)
    /// and its path, if the run wrote one.
    pub(super) fn program(&self, name: &str) -> Option<&WrittenFile> {
        self.find(name_of(name)).map(|index| &self.files[index])
    }

    pub(super) fn into_written(self) -> Vec<WrittenFile> {
        self.files
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_append_lines_that_a_bare_name_finds() {
        let mut files = Files::default();
        let path = "/_N_MPF_DIR/_N_VACKA_DIR/_N_GEOMETRIE_VACKA_SPF";
        assert!(!files.exists("_N_GEOMETRIE_VACKA_SPF"));
        assert_eq!(files.write(path, "G0 X0 Y15"), DONE);
        assert_eq!(files.write(&path.to_lowercase(), "M17"), DONE);
        assert!(files.exists("_n_geometrie_vacka_spf") && files.exists(path));
        assert_eq!(files.read(path, 2, 5), Ok(vec!["M17".to_owned()]));
        assert_eq!(files.read(path, 0, 1), Err(WRONG_TYPE));
        assert_eq!(files.program("_N_GEOMETRIE_VACKA_SPF").map(|file| file.text.as_str()), Some("G0 X0 Y15\nM17\n"));
        assert_eq!(files.write("/_N_MPF_DIR/../X", "x"), PATH_NOT_PERMITTED);
        assert_eq!(files.write(" ", "x"), PATH_NOT_PERMITTED);
        assert_eq!(files.delete("_N_OTHER_SPF"), FILE_NOT_FOUND);
        assert_eq!(files.delete("_N_GEOMETRIE_VACKA_SPF"), DONE);
        assert!(!files.exists(path) && files.into_written().is_empty());
    }
}
