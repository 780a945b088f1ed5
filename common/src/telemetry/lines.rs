//! The lines of a telemetry file, each read within a byte bound (issue 33, item 12): a line
//! longer than the bound is an error as soon as one byte more than the bound has been seen, so a
//! file without a newline (a gigabyte of NUL bytes, a 300 MB line) costs the bound in memory and
//! in reading, not its size. `BufRead::split` would hold the whole line first.

use std::io::BufRead;

/// A line longer than the bound (carried inside the `std::io::Error` of [`BoundedLines`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a line longer than {limit} bytes")]
pub(super) struct LineTooLong {
    /// The bound \[bytes\].
    pub(super) limit: usize,
}

/// The lines of `reader` without their `\n` (as `BufRead::split(b'\n')` gives them), each at
/// most `limit` bytes; the first longer line is an error, after which nothing more is read.
pub(super) struct BoundedLines<R> {
    reader: R,
    limit: usize,
    finished: bool,
}

impl<R: BufRead> BoundedLines<R> {
    /// The lines of `reader`, each at most `limit` bytes.
    pub(super) fn new(reader: R, limit: usize) -> Self {
        BoundedLines {
            reader,
            limit,
            finished: false,
        }
    }

    /// The next line: `Ok(None)` at the end of the input.
    fn next_line(&mut self) -> std::io::Result<Option<Vec<u8>>> {
        let mut line = Vec::new();
        loop {
            let buf = match self.reader.fill_buf() {
                Ok(buf) => buf,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if buf.is_empty() {
                // The end: a last line without its newline, or nothing after the last one.
                return Ok((!line.is_empty()).then_some(line));
            }
            let newline = buf.iter().position(|&b| b == b'\n');
            let take = newline.unwrap_or(buf.len());
            if line.len() + take > self.limit {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    LineTooLong { limit: self.limit },
                ));
            }
            line.extend_from_slice(&buf[..take]);
            let consumed = take + usize::from(newline.is_some());
            self.reader.consume(consumed);
            if newline.is_some() {
                return Ok(Some(line));
            }
        }
    }
}

impl<R: BufRead> Iterator for BoundedLines<R> {
    type Item = std::io::Result<Vec<u8>>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.finished {
            return None;
        }
        let next = self.next_line();
        if !matches!(next, Ok(Some(_))) {
            self.finished = true;
        }
        next.transpose()
    }
}

/// The bound carried by an I/O error of [`BoundedLines`], if it is one.
pub(super) fn too_long(e: &std::io::Error) -> Option<usize> {
    e.get_ref()
        .and_then(|inner| inner.downcast_ref::<LineTooLong>())
        .map(|t| t.limit)
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
