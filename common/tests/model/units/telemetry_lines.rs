//! The unit tests of `sepval_common::telemetry::lines`.

use sepval_common::internals::{BoundedLines, too_long};
use std::io::Read;

fn lines(text: &[u8], limit: usize) -> Vec<std::io::Result<Vec<u8>>> {
    BoundedLines::new(std::io::BufReader::with_capacity(4, text), limit).collect()
}

#[test]
fn lines_are_those_of_split_within_the_bound() {
    for text in [
        &b""[..],
        b"a",
        b"a\n",
        b"a\n\nbc",
        b"\n",
        b"abc\ndef\n",
        b"t_s,x_m\n0,1",
    ] {
        let ours: Vec<Vec<u8>> = lines(text, 16).into_iter().map(|l| l.unwrap()).collect();
        let std: Vec<Vec<u8>> = text.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
        // `split` of a slice gives an empty last piece after a final newline; `BufRead::split`
        // does not.
        let std = match std.last() {
            Some(last) if last.is_empty() => std[..std.len() - 1].to_vec(),
            _ => std,
        };
        assert_eq!(ours, std, "{:?}", String::from_utf8_lossy(text));
    }
}

#[test]
fn a_line_longer_than_the_bound_stops_the_reading_at_the_bound() {
    let got = lines(b"abcd\nabcdefgh\nab\n", 4);
    assert_eq!(got[0].as_ref().unwrap(), b"abcd");
    assert_eq!(too_long(got[1].as_ref().unwrap_err()), Some(4));
    assert_eq!(got.len(), 2, "nothing is read after the long line");

    // A gigabyte of NUL bytes without a newline: refused having read the bound and one
    // buffer more, never the gigabyte.
    struct Counted<R>(R, u64);
    impl<R: Read> Read for Counted<R> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.0.read(buf)?;
            self.1 += n as u64;
            Ok(n)
        }
    }
    let mut counted = Counted(std::io::repeat(0).take(1 << 30), 0);
    let bound = sepval_core::limits::MAX_TELEMETRY_LINE_BYTES;
    let first = BoundedLines::new(std::io::BufReader::new(&mut counted), bound).next();
    assert_eq!(too_long(&first.unwrap().unwrap_err()), Some(bound));
    assert!(
        counted.1 <= (bound + 8192) as u64,
        "read {} bytes",
        counted.1
    );
}
