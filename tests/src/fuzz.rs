//! The shared parts of the property-based tests that feed arbitrary and mutated input to every
//! reader of outside input (`common/tests/model/fuzz.rs`, `transport/src/fuzz_tests.rs`,
//! `coordinator/tests/cli/fuzz.rs`): their configuration, an allocator that records the largest
//! allocation a call makes, structured mutations of a valid input, and the kinds of path a
//! reader may be given instead of a regular file ([`PathKind`], awaited with
//! [`within_deadline`]).
//!
//! # Running more cases
//!
//! Each property runs a bounded number of cases (a few seconds in all per test binary) drawn
//! from a fixed seed, so that every run draws the same cases and a failure reproduces with the
//! same command. `PROPTEST_CASES=N` runs N cases of every property instead and
//! `PROPTEST_RNG_SEED=S` draws other cases, e.g.
//!
//! ```sh
//! PROPTEST_CASES=20000 PROPTEST_RNG_SEED=7 cargo test --release -p sepval-common --test model fuzz
//! ```
//!
//! A failure prints its smallest failing input and is recorded under `proptest-regressions/`
//! beside the test (replayed first by later runs); the input belongs in a regular unit test next
//! to the fix, and the record need not be kept.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::{RngSeed, TestCaseError};

/// The seed of every property's cases unless `PROPTEST_RNG_SEED` says otherwise.
pub const SEED: u64 = 0x5e9_7a1;

/// The configuration of a property: `cases` cases (`PROPTEST_CASES` overrides), the fixed
/// [`SEED`] (`PROPTEST_RNG_SEED` overrides), proptest's defaults otherwise.
pub fn config(cases: u32) -> ProptestConfig {
    fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
        std::env::var(name).ok().and_then(|v| v.trim().parse().ok())
    }
    ProptestConfig {
        cases: env("PROPTEST_CASES").unwrap_or(cases),
        rng_seed: RngSeed::Fixed(env("PROPTEST_RNG_SEED").unwrap_or(SEED)),
        ..ProptestConfig::default()
    }
}

thread_local! {
    /// The largest allocation (or reallocation) this thread made since [`measure`] reset it.
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, recording the largest allocation of each thread. A test binary that
/// checks allocations installs it:
///
/// ```ignore
/// #[global_allocator]
/// static ALLOCATOR: sepval_tests::fuzz::CountingAllocator = sepval_tests::fuzz::CountingAllocator;
/// ```
pub struct CountingAllocator;

fn note(size: usize) {
    // A const-initialised cell without destructor: no allocation, usable from any thread.
    let _ = LARGEST.try_with(|c| c.set(c.get().max(size)));
}

// SAFETY: every call is passed on unchanged to the system allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: the caller's contract, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// What a call did besides its result.
#[derive(Debug, Clone, Copy)]
pub struct Cost {
    /// Its largest single allocation \[bytes\] (0 unless [`CountingAllocator`] is installed).
    pub largest_allocation: usize,
    /// Its wall-clock time.
    pub elapsed: Duration,
}

/// Longest a call on an input of a few kilobytes may take: thousands of times what any of them
/// takes, so that only a hang (or work far beyond the input's size) exceeds it.
pub const MAX_CALL: Duration = Duration::from_secs(5);

/// Calls `f` on this thread and measures it.
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, Cost) {
    LARGEST.with(|c| c.set(0));
    let start = Instant::now();
    let value = f();
    let elapsed = start.elapsed();
    let largest_allocation = LARGEST.with(Cell::get);
    (
        value,
        Cost {
            largest_allocation,
            elapsed,
        },
    )
}

/// Fails the case unless `cost` is within bounds: no single allocation above `max_allocation`
/// bytes, no call longer than [`MAX_CALL`].
pub fn check_cost(what: &str, cost: Cost, max_allocation: usize) -> Result<(), TestCaseError> {
    if cost.largest_allocation > max_allocation {
        return Err(TestCaseError::fail(format!(
            "{what}: allocated {} bytes at once, the bound is {max_allocation}",
            cost.largest_allocation
        )));
    }
    if cost.elapsed > MAX_CALL {
        return Err(TestCaseError::fail(format!(
            "{what}: took {:?}, the bound is {MAX_CALL:?}",
            cost.elapsed
        )));
    }
    Ok(())
}

/// Fails the case unless `result` is `Ok` or an error with a message.
pub fn check_typed<T, E: std::fmt::Display>(
    what: &str,
    result: &Result<T, E>,
) -> Result<(), TestCaseError> {
    match result {
        Err(e) if e.to_string().trim().is_empty() => Err(TestCaseError::fail(format!(
            "{what}: an error without a message"
        ))),
        _ => Ok(()),
    }
}

/// Text that breaks a reader where a number stands: beyond every bound, not finite, negative,
/// subnormal, beyond every integer type, not a number at all.
pub const HOSTILE_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-0.0",
    "1",
    "-1",
    "2",
    "3",
    "52",
    "53",
    "64",
    "65",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "-1e309",
    "4e-324",
    "1e-320",
    "2.2250738585072014e-308",
    "1e-12",
    "NaN",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "+inf",
    "infinity",
    "Infinity",
    "3600",
    "3600.0000000000005",
    "-3600.0000000000005",
    "100000.00000000001",
    "11000",
    "90",
    "4000001",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775809",
    "18446744073709551615",
    "18446744073709551616",
    "340282366920938463463374607431768211455",
    "340282366920938463463374607431768211456",
    "99999999999999999999999999999999999999999999999999999999999999999999999999999999",
    "0x10",
    "0b1",
    "1_000",
    "1e",
    "e5",
    ".",
    "-",
    "+",
    "",
    "1.2.3",
    "--1",
];

/// A number as text: one of [`HOSTILE_NUMBERS`], or any double or integer in one of its
/// spellings.
pub fn number_text() -> BoxedStrategy<String> {
    prop_oneof![
        3 => select(HOSTILE_NUMBERS).prop_map(String::from),
        1 => any::<f64>().prop_map(|v| v.to_string()),
        1 => any::<f64>().prop_map(|v| format!("{v:e}")),
        1 => any::<i64>().prop_map(|v| v.to_string()),
        1 => any::<u64>().prop_map(|v| v.to_string()),
    ]
    .boxed()
}

/// A length or count as a binary field: the boundaries of every limit and integer type, and
/// values whose product with an item size overflows.
pub fn length_value() -> BoxedStrategy<u64> {
    const EDGES: &[u64] = &[
        0,
        1,
        2,
        3,
        7,
        8,
        16,
        17,
        23,
        24,
        25,
        55,
        56,
        57,
        240,
        241,
        255,
        256,
        1023,
        1024,
        1025,
        4095,
        4096,
        4097,
        65535,
        65536,
        65537,
        4_000_000,
        4_000_001,
        (1 << 28) - 1,
        1 << 28,
        (1 << 28) + 1,
        (1 << 30) - 1,
        1 << 30,
        (1 << 30) + 1,
        u32::MAX as u64,
        1 << 32,
        1 << 60,
        1 << 63,
        u64::MAX / 56 + 1,
        u64::MAX / 24 + 1,
        u64::MAX / 2,
        u64::MAX - 1,
        u64::MAX,
    ];
    prop_oneof![3 => select(EDGES), 1 => any::<u64>()].boxed()
}

/// A position in an input, as a fraction of its length (`u64::MAX` is the end), so that an edit
/// applies to any input and shrinks towards its start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct At(pub u64);

impl At {
    /// The position in `0..len` (0 when `len` is 0).
    pub fn of(self, len: usize) -> usize {
        ((u128::from(self.0) * len as u128) >> 64) as usize
    }
}

/// Any position.
pub fn at() -> BoxedStrategy<At> {
    any::<u64>().prop_map(At).boxed()
}

/// One edit of an input.
#[derive(Debug, Clone)]
pub enum Edit {
    /// Flips one bit of one byte.
    FlipBit(At, u8),
    /// Sets one byte.
    SetByte(At, u8),
    /// Inserts bytes.
    Insert(At, Vec<u8>),
    /// Deletes up to that many bytes.
    Delete(At, usize),
    /// Cuts the input there.
    Truncate(At),
    /// Repeats a line (up to that many times in all).
    DuplicateLine(At, usize),
    /// Removes a line.
    DeleteLine(At),
    /// Swaps two lines.
    SwapLines(At, At),
    /// Replaces a number of the text (a run of digits, signs, points and exponents).
    ReplaceNumber(At, String),
    /// Writes a little-endian u64 over one of the input's length fields (binary inputs).
    SetLength(At, u64),
    /// Writes a little-endian u64 at a 4-byte aligned offset (binary inputs).
    SetU64(At, u64),
}

/// Edits of a text: byte-level edits, insertions of `tokens` (the format's own syntax, where
/// the reader makes its decisions), line edits and numbers replaced by hostile ones.
pub fn text_edit(tokens: &'static [&'static str]) -> BoxedStrategy<Edit> {
    prop_oneof![
        1 => (at(), 0..8u8).prop_map(|(i, b)| Edit::FlipBit(i, b)),
        1 => (at(), any::<u8>()).prop_map(|(i, b)| Edit::SetByte(i, b)),
        2 => (at(), select(tokens)).prop_map(|(i, t)| Edit::Insert(i, t.as_bytes().to_vec())),
        1 => (at(), prop::collection::vec(any::<u8>(), 1..16)).prop_map(|(i, b)| Edit::Insert(i, b)),
        1 => (at(), 1..64usize).prop_map(|(i, n)| Edit::Delete(i, n)),
        1 => at().prop_map(Edit::Truncate),
        2 => (at(), 2..64usize).prop_map(|(i, n)| Edit::DuplicateLine(i, n)),
        1 => at().prop_map(Edit::DeleteLine),
        1 => (at(), at()).prop_map(|(a, b)| Edit::SwapLines(a, b)),
        4 => (at(), number_text()).prop_map(|(i, t)| Edit::ReplaceNumber(i, t)),
    ]
    .boxed()
}

/// Edits of a binary message: byte-level edits, and length fields and aligned words set to
/// hostile counts.
pub fn binary_edit() -> BoxedStrategy<Edit> {
    prop_oneof![
        2 => (at(), 0..8u8).prop_map(|(i, b)| Edit::FlipBit(i, b)),
        1 => (at(), any::<u8>()).prop_map(|(i, b)| Edit::SetByte(i, b)),
        1 => (at(), prop::collection::vec(any::<u8>(), 1..24)).prop_map(|(i, b)| Edit::Insert(i, b)),
        1 => (at(), 1..64usize).prop_map(|(i, n)| Edit::Delete(i, n)),
        1 => at().prop_map(Edit::Truncate),
        4 => (at(), length_value()).prop_map(|(i, v)| Edit::SetLength(i, v)),
        2 => (at(), length_value()).prop_map(|(i, v)| Edit::SetU64(i, v)),
    ]
    .boxed()
}

/// One to `max` edits drawn from `edit`: as often one or two (which leave most of the input
/// valid, so that the reader goes deep before it meets them) as more.
pub fn edits(edit: BoxedStrategy<Edit>, max: usize) -> BoxedStrategy<Vec<Edit>> {
    prop_oneof![
        prop::collection::vec(edit.clone(), 1..=2.min(max)),
        prop::collection::vec(edit, 1..=max),
    ]
    .boxed()
}

/// One to `max` numbers of a text replaced by hostile ones.
pub fn number_edits(max: usize) -> BoxedStrategy<Vec<Edit>> {
    let replace = (at(), number_text()).prop_map(|(i, t)| Edit::ReplaceNumber(i, t));
    prop::collection::vec(replace, 1..=max).boxed()
}

/// Where the lines of `bytes` are (start, end without the `\n`).
fn lines(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (k, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            out.push((start, k));
            start = k + 1;
        }
    }
    if start < bytes.len() {
        out.push((start, bytes.len()));
    }
    out
}

/// Where the numbers of a text are: maximal runs of digits, points, signs and exponents that
/// hold a digit and follow no letter or underscore (so that `x_m` and `t_s` are not numbers).
fn numbers(bytes: &[u8]) -> Vec<(usize, usize)> {
    let part = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E');
    let mut out = Vec::new();
    let mut k = 0;
    while k < bytes.len() {
        let after_word = k > 0 && (bytes[k - 1].is_ascii_alphanumeric() || bytes[k - 1] == b'_');
        if part(bytes[k]) && !after_word && !matches!(bytes[k], b'e' | b'E') {
            let start = k;
            while k < bytes.len() && part(bytes[k]) {
                k += 1;
            }
            if bytes[start..k].iter().any(u8::is_ascii_digit) {
                out.push((start, k));
            }
        } else {
            k += 1;
        }
    }
    out
}

/// `bytes` after `edits`, in turn; `lengths` are the offsets of the input's u64 length fields
/// (for [`Edit::SetLength`]; edits before it may have moved them, which is one more mutation).
pub fn apply(bytes: &[u8], edits: &[Edit], lengths: &[usize]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for e in edits {
        let at = |i: &At, len: usize| i.of(len);
        match e {
            Edit::FlipBit(i, bit) if !b.is_empty() => {
                let k = at(i, b.len());
                b[k] ^= 1 << bit;
            }
            Edit::SetByte(i, v) if !b.is_empty() => {
                let k = at(i, b.len());
                b[k] = *v;
            }
            Edit::Insert(i, new) => {
                let k = at(i, b.len() + 1);
                b.splice(k..k, new.iter().copied());
            }
            Edit::Delete(i, n) if !b.is_empty() => {
                let k = at(i, b.len());
                let end = (k + n).min(b.len());
                b.drain(k..end);
            }
            Edit::Truncate(i) => {
                let k = at(i, b.len() + 1);
                b.truncate(k);
            }
            Edit::DuplicateLine(i, n) => {
                let ls = lines(&b);
                if !ls.is_empty() {
                    let (s, e) = ls[at(i, ls.len())];
                    let mut line = b[s..e].to_vec();
                    line.push(b'\n');
                    let copies: Vec<u8> = line.repeat(n - 1);
                    b.splice(s..s, copies);
                }
            }
            Edit::DeleteLine(i) => {
                let ls = lines(&b);
                if !ls.is_empty() {
                    let (s, e) = ls[at(i, ls.len())];
                    b.drain(s..(e + 1).min(b.len()));
                }
            }
            Edit::SwapLines(i, j) => {
                let ls = lines(&b);
                if ls.len() >= 2 {
                    let (x, y) = (at(i, ls.len()), at(j, ls.len()));
                    let (first, second) = (ls[x.min(y)], ls[x.max(y)]);
                    if first != second {
                        let mut out = b[..first.0].to_vec();
                        out.extend_from_slice(&b[second.0..second.1]);
                        out.extend_from_slice(&b[first.1..second.0]);
                        out.extend_from_slice(&b[first.0..first.1]);
                        out.extend_from_slice(&b[second.1..]);
                        b = out;
                    }
                }
            }
            Edit::ReplaceNumber(i, text) => {
                let ns = numbers(&b);
                if !ns.is_empty() {
                    let (s, e) = ns[at(i, ns.len())];
                    b.splice(s..e, text.bytes());
                }
            }
            Edit::SetLength(i, v) => {
                let fits: Vec<usize> = lengths
                    .iter()
                    .copied()
                    .filter(|&o| o + 8 <= b.len())
                    .collect();
                if !fits.is_empty() {
                    let o = fits[at(i, fits.len())];
                    b[o..o + 8].copy_from_slice(&v.to_le_bytes());
                }
            }
            Edit::SetU64(i, v) if b.len() >= 8 => {
                let o = at(i, (b.len() - 8) / 4 + 1) * 4;
                b[o..o + 8].copy_from_slice(&v.to_le_bytes());
            }
            _ => {}
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found_and_names_are_not() {
        let text = b"t_s,x_m\n-0.5,1e-3\nmach = 0.95 # 26 000 ft\n";
        let found: Vec<&[u8]> = numbers(text).iter().map(|&(s, e)| &text[s..e]).collect();
        assert_eq!(found, [&b"-0.5"[..], b"1e-3", b"0.95", b"26", b"000"]);
    }

    #[test]
    fn line_edits_keep_the_other_lines() {
        let text = b"a\nbb\nccc\n";
        let (first, last) = (At(0), At(u64::MAX));
        assert_eq!(
            apply(text, &[Edit::SwapLines(first, last)], &[]),
            b"ccc\nbb\na\n"
        );
        assert_eq!(
            apply(text, &[Edit::DuplicateLine(first, 3)], &[]),
            b"a\na\na\nbb\nccc\n"
        );
        assert_eq!(apply(text, &[Edit::DeleteLine(last)], &[]), b"a\nbb\n");
        let mut binary = vec![0u8; 16];
        binary = apply(&binary, &[Edit::SetLength(first, u64::MAX)], &[4]);
        assert_eq!(&binary[4..12], &[0xff; 8]);
    }
}

/// A kind of path a user may give where a file is read: a regular file of some size (its bytes
/// the caller's), or what is not a regular file (issue 21, items 1 and 2).
#[derive(Debug, Clone, PartialEq)]
pub enum PathKind {
    /// A regular file holding the caller's bytes.
    Regular,
    /// A sparse regular file of this many bytes beyond the reader's limit (nothing written).
    OverLimit(u64),
    /// A directory.
    Directory,
    /// A FIFO with no writer (a blocking open would wait for good).
    Fifo,
    /// A character device that never ends (`/dev/zero`).
    DevZero,
    /// A character device that is empty (`/dev/null`).
    DevNull,
    /// A symbolic link to a FIFO (the kind is the target's).
    LinkToFifo,
    /// A path that does not exist.
    Missing,
}

/// Every [`PathKind`], over-limit sizes from one byte beyond to twice the limit's scale.
pub fn path_kind() -> BoxedStrategy<PathKind> {
    prop_oneof![
        2 => Just(PathKind::Regular),
        1 => prop_oneof![Just(1u64), 1..1u64 << 32].prop_map(PathKind::OverLimit),
        1 => Just(PathKind::Directory),
        1 => Just(PathKind::Fifo),
        1 => Just(PathKind::DevZero),
        1 => Just(PathKind::DevNull),
        1 => Just(PathKind::LinkToFifo),
        1 => Just(PathKind::Missing),
    ]
    .boxed()
}

impl PathKind {
    /// Makes the path `name` in `dir` of this kind (`bytes` for a regular file, `limit_bytes`
    /// the reader's limit for an over-limit one) and returns it.
    pub fn make(
        &self,
        dir: &std::path::Path,
        name: &str,
        bytes: &[u8],
        limit_bytes: u64,
    ) -> std::path::PathBuf {
        let path = dir.join(name);
        let mkfifo = |p: &std::path::Path| {
            let ok = std::process::Command::new("mkfifo")
                .arg(p)
                .status()
                .is_ok_and(|s| s.success());
            assert!(ok, "mkfifo {}", p.display());
        };
        match self {
            PathKind::Regular => std::fs::write(&path, bytes).expect("a file in the test's dir"),
            PathKind::OverLimit(extra) => std::fs::File::create(&path)
                .and_then(|f| f.set_len(limit_bytes + extra))
                .expect("a sparse file in the test's dir"),
            PathKind::Directory => std::fs::create_dir(&path).expect("a directory"),
            PathKind::Fifo => mkfifo(&path),
            PathKind::DevZero => return "/dev/zero".into(),
            PathKind::DevNull => return "/dev/null".into(),
            PathKind::LinkToFifo => {
                let target = dir.join(format!("{name}.fifo"));
                mkfifo(&target);
                std::os::unix::fs::symlink(&target, &path).expect("a symbolic link");
            }
            PathKind::Missing => {}
        }
        path
    }

    /// What a refusal of this kind must say (`None` for a regular file, which may be read or
    /// refused for its content, and for a missing one, refused by the system's message).
    pub fn refusal(&self) -> Option<&'static str> {
        match self {
            PathKind::Regular | PathKind::Missing => None,
            PathKind::OverLimit(_) => Some("more than the limit of"),
            PathKind::Directory => Some("is a directory, not a regular file"),
            PathKind::Fifo | PathKind::LinkToFifo => {
                Some("is a FIFO (named pipe), not a regular file")
            }
            PathKind::DevZero | PathKind::DevNull => {
                Some("is a character device, not a regular file")
            }
        }
    }
}

/// Runs `read` in a thread and waits for its answer until [`MAX_CALL`]: a reader that blocks
/// (a FIFO opened without `O_NONBLOCK`) fails the property instead of hanging it.
pub fn within_deadline<T: Send + 'static>(
    what: &str,
    read: impl FnOnce() -> T + Send + 'static,
) -> Result<T, TestCaseError> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(read());
    });
    rx.recv_timeout(MAX_CALL)
        .map_err(|_| TestCaseError::fail(format!("{what}: no answer within {MAX_CALL:?}")))
}
