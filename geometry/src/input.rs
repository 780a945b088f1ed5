//! Reading a geometry file within stated limits: only a regular file (a FIFO, a directory or a
//! device is refused before it is opened), never more than [`MAX_FILE_BYTES`] (checked on the
//! size before reading and again while reading, so a file that grows cannot eat the machine).

use std::io::Read;
use std::path::Path;

use crate::GeometryError;

/// The largest geometry file read: 256 MiB (a binary STL of [`MAX_TRIANGLES`] is 100 MB; an
/// ASCII STL takes about 250 bytes a triangle, so holds about a million within this limit).
pub const MAX_FILE_BYTES: u64 = 256 * 1024 * 1024;

/// The most triangles in one body: 2 million (parry's tree and the mesh then take about 0.5 GB).
pub const MAX_TRIANGLES: u64 = 2_000_000;

/// The bytes of `path`, refused with a typed error when it is not a regular file or too big.
pub(crate) fn read_capped(path: &Path, limit_bytes: u64) -> Result<Vec<u8>, GeometryError> {
    let unreadable = |source| GeometryError::Unreadable {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(unreadable)?;
    let kind = meta.file_type();
    if !kind.is_file() {
        return Err(GeometryError::NotAFile {
            path: path.to_path_buf(),
            kind: if kind.is_dir() {
                "a directory"
            } else {
                "a FIFO, socket or device"
            },
        });
    }
    let too_large = |size_bytes| GeometryError::TooLarge {
        path: path.to_path_buf(),
        size_bytes,
        limit_bytes,
    };
    if meta.len() > limit_bytes {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(unreadable)?;
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > limit_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_over_the_limit_is_refused_with_its_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.stl");
        std::fs::write(&path, vec![b' '; 101]).unwrap();
        let e = read_capped(&path, 100).unwrap_err();
        assert!(
            matches!(
                e,
                GeometryError::TooLarge {
                    size_bytes: 101,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("big.stl"), "{e}");
        assert_eq!(read_capped(&path, 101).unwrap().len(), 101);
    }

    #[test]
    fn a_directory_is_refused_before_it_is_opened() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_capped(dir.path(), 100).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
    }
}
