//! Reading the files a scene names (the scene itself, Matrix Market matrices, DOF lists, start
//! files) with a size bound: a path to `/dev/zero` or a runaway pipe is refused once the bound
//! is passed instead of read until memory runs out.

use std::io::Read;
use std::path::Path;

/// Largest file read (256 MiB): a Matrix Market file of some eight million entries, far
/// above the 10⁵-DOF models the sparse path is built for.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// The text of `path`, at most [`MAX_FILE_BYTES`]; the error says why (unreadable, not
/// UTF-8, too large).
pub fn read_text(path: &Path) -> Result<String, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!(
            "larger than the limit of {} MiB (hbal reads scene, matrix, DOF-list and start files whole)",
            MAX_FILE_BYTES >> 20
        ));
    }
    String::from_utf8(bytes).map_err(|e| format!("not UTF-8 text: {e}"))
}

#[cfg(test)]
mod tests {
    /// An endless file is refused at the bound, not read until memory runs out.
    #[cfg(unix)]
    #[test]
    fn an_endless_file_is_refused_at_the_bound() {
        let e = super::read_text(std::path::Path::new("/dev/zero")).unwrap_err();
        assert!(e.starts_with("larger than the limit of 256 MiB"), "{e}");
    }
}
