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
pub struct BoundedLines<R> {
    reader: R,
    limit: usize,
    finished: bool,
}

impl<R: BufRead> BoundedLines<R> {
    /// The lines of `reader`, each at most `limit` bytes.
    pub fn new(reader: R, limit: usize) -> Self {
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
pub fn too_long(e: &std::io::Error) -> Option<usize> {
    e.get_ref()
        .and_then(|inner| inner.downcast_ref::<LineTooLong>())
        .map(|t| t.limit)
}
