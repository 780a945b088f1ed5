//! The STL reader on arbitrary bytes: an answer, never a panic.

use proptest::prelude::*;
use sepval_geometry::{Body, Role};

use crate::fixtures::{ascii_stl, box_triangles};

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("any.stl");
        std::fs::write(&path, &bytes).unwrap();
        let _ = Body::read(&path, Role::Aircraft);
    }

    #[test]
    fn a_damaged_ascii_file_never_panics(cut in 0usize..2000, byte in any::<u8>()) {
        let mut text = ascii_stl(&[("a", &box_triangles([0.0; 3], [1.0; 3]))]).into_bytes();
        let at = cut % text.len();
        text[at] = byte;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("damaged.stl");
        std::fs::write(&path, &text).unwrap();
        let _ = Body::read(&path, Role::Store);
    }
}
