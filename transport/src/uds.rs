//! The Unix-domain-socket transport: the conventional alternative to shared memory, measured by
//! `sepval bench` beside iceoryx2. The coordinator ([`UdsLink`]) listens on a socket in a fresh
//! temporary directory and spawns `sepval-worker --uds PATH` processes; each worker
//! ([`UdsWorker`]) connects, receives the setup, answers with `Ready`, then answers chunks. Every
//! message is a [`Frame`] behind a little-endian u32 length, copied through the kernel.

use std::io::{Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::channel::{Receiver, RecvTimeoutError, Sender, unbounded};
use sepval_common::evaluation::Job;
use sepval_core::cancel;

use crate::codec::{Frame, MAX_SETUP};
use crate::link::{Incoming, Link, LinkEvent, SendError, Stopped, WorkerId, WorkerLink};
use crate::setup::{decode_setup, encode_setup};
use crate::wire::Answer;
use crate::{RunId, TransportError, io};

/// Largest frame accepted \[bytes\] (a corrupt length must not allocate gigabytes).
pub const MAX_FRAME: usize = MAX_SETUP + (1 << 20);

/// Writes one frame.
fn write_frame(w: &mut impl Write, frame: &Frame) -> std::io::Result<()> {
    let bytes = frame.encode();
    w.write_all(&(bytes.len() as u32).to_le_bytes())?;
    w.write_all(&bytes)?;
    w.flush()
}

/// Bytes of a frame read at a time: the most a frame's length allocates before its bytes
/// have arrived.
const READ_STEP: usize = 64 << 10;

/// Reads one frame; `Ok(None)` at a clean end of the stream.
pub(crate) fn read_frame(r: &mut impl Read) -> Result<Option<Frame>, TransportError> {
    let mut len = [0u8; 4];
    match r.read_exact(&mut len) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(io("reading a frame")(e)),
    }
    let len = u32::from_le_bytes(len) as usize;
    if len > MAX_FRAME {
        return Err(TransportError::FrameTooLong {
            len,
            limit: MAX_FRAME,
        });
    }
    // The buffer grows with the bytes that arrive, a step at a time: a corrupt length (up to
    // MAX_FRAME) allocates one step, not the gigabyte it announces.
    let mut buf = Vec::new();
    while buf.len() < len {
        let at = buf.len();
        buf.resize(at + (len - at).min(READ_STEP), 0);
        r.read_exact(&mut buf[at..])
            .map_err(io(format!("reading a frame of {len} bytes")))?;
    }
    Frame::decode(&buf)
        .map(Some)
        .map_err(|source| TransportError::Codec {
            what: "frame".into(),
            source,
        })
}

/// Reads frames on a thread of its own into `tx` until the stream ends.
fn reader<T: Send + 'static>(
    mut stream: UnixStream,
    tx: Sender<T>,
    wrap: impl Fn(Result<Option<Frame>, TransportError>) -> T + Send + 'static,
) {
    std::thread::spawn(move || {
        loop {
            let r = read_frame(&mut stream);
            let stop = !matches!(r, Ok(Some(_)));
            if tx.send(wrap(r)).is_err() || stop {
                break;
            }
        }
    });
}

type Heard = (WorkerId, Result<Option<Frame>, TransportError>);

/// The coordinator's end of the socket transport.
pub struct UdsLink {
    run_id: RunId,
    listener: UnixListener,
    setup: Frame,
    setup_sha256: [u8; 32],
    streams: std::collections::BTreeMap<WorkerId, UnixStream>,
    children: Vec<Child>,
    heard: Receiver<Heard>,
    tx: Sender<Heard>,
    next_worker: WorkerId,
    _dir: tempfile::TempDir,
}

impl UdsLink {
    /// Listens on a socket in a fresh temporary directory and spawns `workers` worker
    /// processes connected to it.
    pub fn start(job: &Job, workers: usize, executable: &Path) -> Result<UdsLink, TransportError> {
        let dir = tempfile::tempdir().map_err(io("creating the socket directory"))?;
        let path: PathBuf = dir.path().join("sepval.sock");
        let listener = UnixListener::bind(&path).map_err(io("binding the socket"))?;
        listener
            .set_nonblocking(true)
            .map_err(io("configuring the socket"))?;
        let mut children = Vec::new();
        for _ in 0..workers {
            children.push(
                Command::new(executable)
                    .arg("--uds")
                    .arg(&path)
                    .stdin(Stdio::null())
                    .stdout(Stdio::null())
                    .spawn()
                    .map_err(io(format!("cannot start {}", executable.display())))?,
            );
        }
        let run_id = RunId::fresh();
        let (header, bytes) = encode_setup(job);
        let (tx, heard) = unbounded();
        Ok(UdsLink {
            setup: Frame::Setup {
                run_id: run_id.to_string(),
                header,
                bytes,
            },
            setup_sha256: header.sha256,
            run_id,
            listener,
            streams: Default::default(),
            children,
            heard,
            tx,
            next_worker: 0,
            _dir: dir,
        })
    }

    fn accept(&mut self, events: &mut Vec<LinkEvent>) -> Result<(), TransportError> {
        loop {
            match self.listener.accept() {
                Ok((mut s, _)) => {
                    let id = self.next_worker;
                    self.next_worker += 1;
                    s.set_nonblocking(false)
                        .map_err(io("configuring a socket"))?;
                    if let Err(e) = write_frame(&mut s, &self.setup) {
                        events.push(LinkEvent::Lost {
                            worker: id,
                            reason: format!("sending the setup failed: {e}"),
                        });
                        continue;
                    }
                    let read = s.try_clone().map_err(io("cloning a socket"))?;
                    reader(read, self.tx.clone(), move |r| (id, r));
                    self.streams.insert(id, s);
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return Ok(()),
                Err(e) => return Err(io("accepting a worker")(e)),
            }
        }
    }

    fn heard(&mut self, (id, r): Heard, events: &mut Vec<LinkEvent>) {
        let lost = |reason: String| LinkEvent::Lost { worker: id, reason };
        match r {
            Ok(Some(Frame::Ready {
                pid,
                credits,
                setup_sha256,
                ..
            })) if setup_sha256 == self.setup_sha256 => events.push(LinkEvent::Joined {
                worker: id,
                label: format!("pid {pid}"),
                credits: credits as usize,
            }),
            Ok(Some(Frame::Answer(answer))) => {
                events.push(LinkEvent::Answer { worker: id, answer })
            }
            Ok(Some(other)) => events.push(lost(format!(
                "unexpected message: {}",
                Frame::name_of(Some(&other))
            ))),
            Ok(None) => events.push(lost("its socket closed".into())),
            Err(e) => events.push(lost(crate::error_chain(&e))),
        }
    }
}

impl Link for UdsLink {
    fn send(&mut self, worker: WorkerId, chunk: &crate::wire::Chunk) -> Result<(), SendError> {
        let s = self
            .streams
            .get_mut(&worker)
            .ok_or(SendError::NoWorker { worker })?;
        write_frame(s, &Frame::Chunk(chunk.clone())).map_err(SendError::Write)
    }

    fn poll(
        &mut self,
        timeout: Duration,
        events: &mut Vec<LinkEvent>,
    ) -> Result<(), TransportError> {
        cancel::check()?;
        self.accept(events)?;
        match self.heard.recv_timeout(timeout) {
            Ok(h) => self.heard(h, events),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => unreachable!("the link holds a sender"),
        }
        while let Ok(h) = self.heard.try_recv() {
            self.heard(h, events);
        }
        Ok(())
    }

    fn drop_worker(&mut self, worker: WorkerId, _reason: &str) -> &'static str {
        if let Some(s) = self.streams.remove(&worker) {
            let _ = s.shutdown(std::net::Shutdown::Both);
        }
        "disconnected"
    }

    fn replacement_wait(&self) -> Duration {
        Duration::ZERO
    }

    fn run_id(&self) -> &str {
        self.run_id.as_str()
    }

    fn describe(&self) -> String {
        "uds".to_string()
    }
}

impl Drop for UdsLink {
    fn drop(&mut self) {
        // Closing the sockets ends the workers (end of file).
        for s in self.streams.values() {
            let _ = s.shutdown(std::net::Shutdown::Both);
        }
        self.streams.clear();
        let until = Instant::now() + Duration::from_secs(2);
        for c in self.children.iter_mut() {
            while matches!(c.try_wait(), Ok(None)) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(2));
            }
            if matches!(c.try_wait(), Ok(None)) {
                let _ = c.kill();
            }
            let _ = c.wait();
        }
    }
}

/// A worker's end of the socket transport.
pub struct UdsWorker {
    stream: UnixStream,
    job: Arc<Job>,
    heard: Receiver<Result<Option<Frame>, TransportError>>,
}

impl UdsWorker {
    /// Connects to the coordinator's socket, reads and checks the setup, and says it is ready.
    pub fn join(path: &Path, setup_timeout: Duration) -> Result<UdsWorker, TransportError> {
        let mut stream = UnixStream::connect(path)
            .map_err(io(format!("cannot connect to {}", path.display())))?;
        stream
            .set_read_timeout(Some(setup_timeout))
            .map_err(io("configuring the socket"))?;
        let (job, setup_sha256) = match read_frame(&mut stream)? {
            Some(Frame::Setup { header, bytes, .. }) => {
                (decode_setup(&header, &bytes)?, header.sha256)
            }
            other => {
                return Err(TransportError::SetupNotFirst {
                    frame: Frame::name_of(other.as_ref()),
                });
            }
        };
        stream
            .set_read_timeout(None)
            .map_err(io("configuring the socket"))?;
        let ready = Frame::Ready {
            pid: std::process::id(),
            credits: 2,
            setup_sha256,
            host: String::new(),
        };
        write_frame(&mut stream, &ready).map_err(io("saying ready"))?;
        let (tx, heard) = unbounded();
        reader(
            stream.try_clone().map_err(io("cloning the socket"))?,
            tx,
            |r| r,
        );
        Ok(UdsWorker {
            stream,
            job: Arc::new(job),
            heard,
        })
    }

    /// The job of the accepted setup.
    pub fn job(&self) -> &Arc<Job> {
        &self.job
    }
}

impl WorkerLink for UdsWorker {
    fn receive(&mut self, timeout: Duration) -> Result<Incoming, TransportError> {
        if cancel::requested() {
            return Ok(Incoming::Stop(Stopped::Signal));
        }
        let r = match self.heard.recv_timeout(timeout) {
            Ok(r) => r,
            Err(RecvTimeoutError::Timeout) => return Ok(Incoming::Idle),
            Err(RecvTimeoutError::Disconnected) => Ok(None),
        };
        match r? {
            Some(frame) => frame.into_incoming(),
            None => Ok(Incoming::Stop(Stopped::Quit(
                "the coordinator closed the connection".into(),
            ))),
        }
    }

    fn answer(&mut self, answer: &Answer) -> Result<(), TransportError> {
        write_frame(&mut self.stream, &Frame::Answer(answer.clone()))
            .map_err(io("answering a chunk"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A length far beyond the bytes that follow is refused without allocating it (found by
    /// `fuzz_tests::stream_frames`: it allocated the whole announced length, up to 1 GiB,
    /// before reading).
    #[test]
    fn a_frame_longer_than_its_stream_allocates_one_step() {
        let mut stream = (MAX_FRAME as u32).to_le_bytes().to_vec();
        stream.extend_from_slice(&Frame::Quit("x".into()).encode());
        let (result, cost) =
            sepval_tests::fuzz::measure(|| read_frame(&mut std::io::Cursor::new(&stream)));
        let e = result.unwrap_err().to_string();
        assert!(
            e.contains(&format!("reading a frame of {MAX_FRAME} bytes")),
            "{e}"
        );
        // The test binary counts allocations (crate::fuzz_tests).
        assert!(cost.largest_allocation <= READ_STEP, "{cost:?}");
        // A frame that is all there reads whatever its size.
        let setup = Frame::Setup {
            run_id: "r".into(),
            header: crate::wire::SetupHeader::default(),
            bytes: vec![7; 3 * READ_STEP + 5],
        };
        let mut stream = (setup.encode().len() as u32).to_le_bytes().to_vec();
        stream.extend_from_slice(&setup.encode());
        let back = read_frame(&mut std::io::Cursor::new(&stream)).unwrap();
        assert_eq!(back, Some(setup));
    }
}
