//! LinuxCNC's `rs274` interpreter, the executor's peer: the differential
//! test and the `exec` benchmark run it on the NGC form of a toolpath.

use std::path::PathBuf;

/// What to do when it is missing.
pub const MISSING: &str = "rs274 not found: install Debian's linuxcnc-uspace";

/// `rs274` on the PATH, else where Debian's linuxcnc-uspace puts it.
pub fn find() -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain([PathBuf::from("/usr/bin")])
        .map(|dir| dir.join("rs274"))
        .find(|candidate| candidate.is_file())
}
