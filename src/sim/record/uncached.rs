//! The file a recording streams into: written by a thread of its own, past the kernel's
//! page cache where the system allows it.
//!
//! Why: a recorded campaign writes gigabytes of raw frames, and the sensor noise in them
//! leaves them nearly incompressible (zstd's fastest level saves 30 % for more CPU than
//! the write costs; LZ4 saves 4 %). Written through the page cache, every byte is copied
//! by the kernel into a cache page, written back by a kernel thread, and the writer is
//! throttled while dirty pages pile up: 12.7 s of kernel time in a 95 s campaign on the
//! 2-core build machine. On Linux the file is opened with `O_DIRECT`, so the disk reads
//! each block straight from our buffer, and the writes happen on a writer thread, so the
//! simulation does not wait for the disk.
//!
//! `O_DIRECT` wants the buffer's address, the file offset and the length of every
//! transfer aligned to the device's block ([`ALIGN`]). The stream is staged in aligned
//! segments of [`SEGMENT`] bytes; a full segment goes to the writer thread and an empty
//! one comes back (a pool of [`SEGMENTS`], so the simulation waits only when the disk is
//! that far behind). The MCAP writer seeks back over its current chunk to patch the
//! chunk's header: in the current segment that is a write to memory; further back, the
//! header's fields are gathered into one patch, and the writer thread reads the aligned
//! blocks around it, patches them and writes them back, after the segments before it. [`std::io::Write::flush`] waits for the thread to write
//! everything, the last segment padded to a whole block, and truncates the file to the
//! stream's length.
//!
//! Where `O_DIRECT` is refused (a file system without it, such as an older tmpfs, or a
//! system other than Linux) the same code writes through the page cache. The file's bytes
//! are the same either way.

use std::fs::{File, OpenOptions};
use std::io::{self, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, Sender, channel, sync_channel};
use std::thread::JoinHandle;

/// Alignment of every direct transfer: address, offset and length (a page; any block
/// device's logical block divides it).
const ALIGN: usize = 4096;
/// Bytes staged in one segment (about a millisecond of the disk's time).
const SEGMENT: usize = 2 << 20;
/// Segments per file: one being filled, the others being written or free.
const SEGMENTS: usize = 3;
/// Segments kept for the next files once a file is closed, so that a campaign's files
/// do not each fault in fresh memory.
const SPARE: usize = 4 * SEGMENTS;

/// Segments of closed files, for the next ones.
static SPARES: std::sync::Mutex<Vec<Segment>> = std::sync::Mutex::new(Vec::new());

/// An aligned buffer (empty by default: a placeholder while the real one is away).
#[derive(Default)]
struct Segment {
    /// Backing store, [`ALIGN`] bytes longer than the segment.
    mem: Vec<u8>,
    /// Offset of the aligned start in `mem`.
    base: usize,
}

impl Segment {
    fn new(len: usize) -> Self {
        let mem = vec![0u8; len + ALIGN];
        let base = mem.as_ptr().align_offset(ALIGN);
        Self { mem, base }
    }

    /// A segment of `len` bytes, a spare one if there is one (its bytes are stale).
    fn reuse(len: usize) -> Self {
        let spare = SPARES.lock().ok().and_then(|mut s| {
            let i = s.iter().position(|g| g.mem.len() == len + ALIGN)?;
            Some(s.swap_remove(i))
        });
        spare.unwrap_or_else(|| Self::new(len))
    }

    /// Keeps the segment for a later file, if there is room.
    fn retire(self) {
        if self.mem.is_empty() {
            return;
        }
        if let Ok(mut s) = SPARES.lock()
            && s.len() < SPARE
        {
            s.push(self);
        }
    }

    fn bytes(&self, len: usize) -> &[u8] {
        &self.mem[self.base..self.base + len]
    }

    fn bytes_mut(&mut self, len: usize) -> &mut [u8] {
        &mut self.mem[self.base..self.base + len]
    }
}

/// Work for the writer thread, done in order.
enum Job {
    /// Write `len` bytes of the segment at `offset`, then hand the segment back.
    Write { offset: u64, segment: Segment, len: usize },
    /// Overwrite bytes already written (a chunk header's fields, gathered into one run).
    Patch { offset: u64, bytes: Vec<u8> },
    /// Write `len` bytes of the segment at `offset` padded to a block, truncate the file
    /// to `end`, and answer with the segment and the first error so far.
    Finish {
        offset: u64,
        segment: Segment,
        len: usize,
        end: u64,
        done: Sender<(Segment, io::Result<()>)>,
    },
}

/// A file written front to back, with seeks back (see the module docs).
pub struct UncachedFile {
    path: PathBuf,
    /// Bytes per segment ([`SEGMENT`]; smaller in tests).
    segment_len: usize,
    /// The segment being filled, which holds the stream from `start`.
    current: Segment,
    /// Stream offset of the current segment's first byte, a multiple of `segment_len`.
    start: u64,
    /// Bytes written over the stream before `start`, gathered until the cursor leaves
    /// them (the MCAP writer patches a chunk's header a field at a time), so the thread
    /// reads and rewrites their blocks once.
    patch: Vec<u8>,
    /// Stream offset of `patch`'s first byte.
    patch_at: u64,
    /// The cursor.
    pos: u64,
    /// The stream's length.
    end: u64,
    jobs: Option<Sender<Job>>,
    /// Segments the thread is done with, with the thread's first error.
    free: Receiver<(Segment, Option<io::ErrorKind>)>,
    thread: Option<JoinHandle<()>>,
    /// The first error the thread met.
    failed: Option<io::ErrorKind>,
    /// Written to since the last flush.
    dirty: bool,
}

impl UncachedFile {
    /// Creates (or truncates) `path` and starts its writer thread.
    ///
    /// # Errors
    /// The error of opening the file or starting the thread.
    pub(super) fn create(path: &Path) -> io::Result<Self> {
        Self::with_segments(path, SEGMENT, SEGMENTS, true)
    }

    /// [`UncachedFile::create`] with `count` segments of `len` bytes (a multiple of
    /// [`ALIGN`]; `count` at least 2), past the page cache if `direct` and allowed.
    fn with_segments(path: &Path, len: usize, count: usize, direct: bool) -> io::Result<Self> {
        debug_assert!(len.is_multiple_of(ALIGN) && len > 0 && count >= 2);
        let (file, direct) = match open(path, direct, true) {
            Ok(f) => (f, direct),
            Err(e) if refused(&e) => (open(path, false, true)?, false),
            Err(e) => return Err(e),
        };
        let (jobs, todo) = channel::<Job>();
        let (give, free) = sync_channel(count);
        for _ in 1..count {
            give.send((Segment::reuse(len), None))
                .map_err(|_| io::ErrorKind::BrokenPipe)?;
        }
        let mut disk = Disk {
            file,
            path: path.to_path_buf(),
            direct,
            failed: None,
            scratch: Segment::default(),
        };
        let thread = std::thread::Builder::new()
            .name("recording-writer".into())
            .spawn(move || disk.serve(todo, give))?;
        Ok(Self {
            path: path.to_path_buf(),
            segment_len: len,
            current: Segment::reuse(len),
            start: 0,
            patch: Vec::new(),
            patch_at: 0,
            pos: 0,
            end: 0,
            jobs: Some(jobs),
            free,
            thread: Some(thread),
            failed: None,
            dirty: true,
        })
    }

    /// Sends `job` to the writer thread. If the thread is gone, a segment the job held
    /// comes back as the current one.
    fn send(&mut self, job: Job) -> io::Result<()> {
        match self.jobs.as_ref().map(|j| j.send(job)) {
            Some(Ok(())) => Ok(()),
            Some(Err(std::sync::mpsc::SendError(Job::Finish { segment, .. }))) => {
                self.current = segment;
                Err(self.broken())
            }
            _ => Err(self.broken()),
        }
    }

    /// A free segment, waiting for the thread if none is.
    fn take_free(&mut self) -> io::Result<Segment> {
        match self.free.recv() {
            Ok((segment, failed)) => {
                if let Some(kind) = failed {
                    self.failed.get_or_insert(kind);
                }
                match self.failed {
                    Some(kind) => Err(self.error(kind)),
                    None => Ok(segment),
                }
            }
            Err(_) => Err(self.broken()),
        }
    }

    fn error(&self, kind: io::ErrorKind) -> io::Error {
        io::Error::new(
            kind,
            format!("{}: the recording's writer failed ({kind})", self.path.display()),
        )
    }

    /// The writer thread is gone: the file fails from here on (so no write touches a
    /// segment the thread took with it).
    fn broken(&mut self) -> io::Error {
        self.failed.get_or_insert(io::ErrorKind::BrokenPipe);
        io::Error::new(
            io::ErrorKind::BrokenPipe,
            format!("{}: the recording's writer thread stopped", self.path.display()),
        )
    }

    /// Sends the gathered patch, if any, to the thread.
    fn send_patch(&mut self) -> io::Result<()> {
        if self.patch.is_empty() {
            return Ok(());
        }
        let bytes = std::mem::take(&mut self.patch);
        self.send(Job::Patch {
            offset: self.patch_at,
            bytes,
        })
    }

    /// Hands the full current segment to the thread and starts the next.
    fn spill(&mut self) -> io::Result<()> {
        let next = self.take_free()?;
        let full = std::mem::replace(&mut self.current, next);
        self.send(Job::Write {
            offset: self.start,
            segment: full,
            len: self.segment_len,
        })?;
        self.start += self.segment_len as u64;
        Ok(())
    }
}

impl Write for UncachedFile {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        if data.is_empty() {
            return Ok(0);
        }
        if let Some(kind) = self.failed {
            return Err(self.error(kind));
        }
        if self.pos < self.start {
            let n = data.len().min((self.start - self.pos) as usize);
            if self.patch_at + self.patch.len() as u64 != self.pos {
                self.send_patch()?;
                self.patch_at = self.pos;
            }
            self.patch.extend_from_slice(&data[..n]);
            self.dirty = true;
            self.pos += n as u64;
            return Ok(n);
        }
        self.send_patch()?;
        let mut i = (self.pos - self.start) as usize;
        if i == self.segment_len {
            self.spill()?;
            i = 0;
        }
        self.dirty = true;
        let n = data.len().min(self.segment_len - i);
        self.current.bytes_mut(self.segment_len)[i..i + n].copy_from_slice(&data[..n]);
        self.pos += n as u64;
        self.end = self.end.max(self.pos);
        Ok(n)
    }

    /// Waits until the file holds the whole stream (the current segment written padded
    /// to a block, the file truncated to the stream's length). Writing can go on.
    fn flush(&mut self) -> io::Result<()> {
        if let Some(kind) = self.failed {
            return Err(self.error(kind));
        }
        self.send_patch()?;
        // The current segment goes to the thread and comes back with the answer.
        let segment = std::mem::take(&mut self.current);
        let (done, answer) = channel();
        self.send(Job::Finish {
            offset: self.start,
            segment,
            len: (self.end - self.start) as usize,
            end: self.end,
            done,
        })?;
        let Ok((segment, result)) = answer.recv() else {
            return Err(self.broken());
        };
        self.current = segment;
        match result {
            Ok(()) => {
                self.dirty = false;
                Ok(())
            }
            Err(e) => {
                self.failed.get_or_insert(e.kind());
                Err(e)
            }
        }
    }
}

impl Seek for UncachedFile {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let target = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => self.end.checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        match target {
            Some(p) if p <= self.end => {
                self.pos = p;
                Ok(p)
            }
            _ => Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a recording's file is written front to back: no seek past its end",
            )),
        }
    }
}

impl Drop for UncachedFile {
    /// Writes what is left, as a `BufWriter` would (errors are lost: call `flush`), and
    /// stops the thread.
    fn drop(&mut self) {
        if self.dirty && self.failed.is_none() {
            let _ = self.flush();
        }
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        std::mem::take(&mut self.current).retire();
        while let Ok((segment, _)) = self.free.try_recv() {
            segment.retire();
        }
    }
}

/// The writer thread's side: the file.
struct Disk {
    file: File,
    path: PathBuf,
    direct: bool,
    failed: Option<io::Error>,
    /// The blocks around a patch, reused from patch to patch.
    scratch: Segment,
}

impl Disk {
    /// Does the jobs in order until the file's [`UncachedFile`] hangs up. After an
    /// error, only hands segments back.
    fn serve(&mut self, todo: Receiver<Job>, give: std::sync::mpsc::SyncSender<(Segment, Option<io::ErrorKind>)>) {
        for job in todo {
            match job {
                Job::Write { offset, segment, len } => {
                    if self.failed.is_none() {
                        let r = self.write(segment.bytes(len), offset);
                        self.note(r);
                    }
                    let _ = give.send((segment, self.failed.as_ref().map(io::Error::kind)));
                }
                Job::Patch { offset, bytes } => {
                    if self.failed.is_none() {
                        let r = self.patch(offset, &bytes);
                        self.note(r);
                    }
                }
                Job::Finish {
                    offset,
                    segment,
                    len,
                    end,
                    done,
                } => {
                    if self.failed.is_none() {
                        let padded = if self.direct { len.div_ceil(ALIGN) * ALIGN } else { len };
                        let r = self.write(segment.bytes(padded), offset);
                        self.note(r);
                    }
                    if self.failed.is_none() {
                        let r = self.file.set_len(end);
                        self.note(r);
                    }
                    let answer = match &self.failed {
                        None => Ok(()),
                        Some(e) => Err(io::Error::new(e.kind(), format!("{}: {e}", self.path.display()))),
                    };
                    let _ = done.send((segment, answer));
                }
            }
        }
    }

    fn note(&mut self, r: io::Result<()>) {
        if let Err(e) = r {
            self.failed.get_or_insert(e);
        }
    }

    /// Writes `buf` at `offset`; when the file system refuses a direct transfer, reopens
    /// the file through the page cache and writes again.
    fn write(&mut self, buf: &[u8], offset: u64) -> io::Result<()> {
        match write_at(&self.file, buf, offset) {
            Err(e) if self.direct && refused(&e) => {
                self.cached()?;
                write_at(&self.file, buf, offset)
            }
            r => r,
        }
    }

    /// Gives up `O_DIRECT` for the rest of the file.
    fn cached(&mut self) -> io::Result<()> {
        self.file = open(&self.path, false, false)?;
        self.direct = false;
        Ok(())
    }

    /// Writes `data` over bytes already in the file at `offset`: directly, the aligned
    /// blocks around it are read, patched and written back.
    fn patch(&mut self, offset: u64, data: &[u8]) -> io::Result<()> {
        if !self.direct {
            return write_at(&self.file, data, offset);
        }
        let a = ALIGN as u64;
        let first = offset / a * a;
        let last = (offset + data.len() as u64).div_ceil(a) * a;
        let n = (last - first) as usize;
        if self.scratch.mem.len() < n + ALIGN {
            self.scratch = Segment::new(n);
        }
        let at = (offset - first) as usize;
        match read_at(&self.file, self.scratch.bytes_mut(n), first) {
            Ok(()) => {
                self.scratch.bytes_mut(n)[at..at + data.len()].copy_from_slice(data);
                let blocks = std::mem::take(&mut self.scratch);
                let r = self.write(blocks.bytes(n), first);
                self.scratch = blocks;
                r
            }
            Err(e) if refused(&e) => {
                self.cached()?;
                write_at(&self.file, data, offset)
            }
            Err(e) => Err(e),
        }
    }
}

/// The file system refused a direct open or transfer.
fn refused(e: &io::Error) -> bool {
    e.kind() == io::ErrorKind::InvalidInput
}

/// Opens `path` for reading and writing, direct or not, truncating it or not.
fn open(path: &Path, direct: bool, truncate: bool) -> io::Result<File> {
    let mut o = OpenOptions::new();
    o.read(true).write(true).create(true).truncate(truncate);
    #[cfg(target_os = "linux")]
    if direct {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_DIRECT);
    }
    #[cfg(not(target_os = "linux"))]
    if direct {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, "no O_DIRECT here"));
    }
    o.open(path)
}

#[cfg(unix)]
fn write_at(file: &File, buf: &[u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::write_all_at(file, buf, offset)
}

#[cfg(unix)]
fn read_at(file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
}

#[cfg(not(unix))]
fn write_at(mut file: &File, buf: &[u8], offset: u64) -> io::Result<()> {
    file.seek(SeekFrom::Start(offset))?;
    file.write_all(buf)
}

#[cfg(not(unix))]
fn read_at(mut file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    use std::io::Read;
    file.seek(SeekFrom::Start(offset))?;
    file.read_exact(buf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// One step of a writer's life: append, or seek back and overwrite.
    #[derive(Debug, Clone)]
    enum Op {
        Append(usize, u8),
        Patch(u64, usize, u8),
    }

    fn op() -> impl Strategy<Value = Op> {
        prop_oneof![
            4 => (1usize..30_000, any::<u8>()).prop_map(|(n, b)| Op::Append(n, b)),
            1 => (any::<u64>(), 1usize..12_000, any::<u8>()).prop_map(|(at, n, b)| Op::Patch(at, n, b)),
        ]
    }

    /// Runs `ops` on the file and on a `Vec` (the reference), patches within the
    /// stream; returns both.
    fn run(path: &Path, ops: &[Op], flush_every: Option<usize>, direct: bool) -> (Vec<u8>, Vec<u8>) {
        // Segments of 16 KiB: patches land in the current segment and far behind it.
        let mut f = UncachedFile::with_segments(path, 16 << 10, 3, direct).unwrap();
        let mut reference: Vec<u8> = Vec::new();
        for (k, op) in ops.iter().enumerate() {
            match *op {
                Op::Append(n, b) => {
                    f.seek(SeekFrom::End(0)).unwrap();
                    let data: Vec<u8> = (0..n).map(|i| b.wrapping_add(i as u8)).collect();
                    f.write_all(&data).unwrap();
                    reference.extend_from_slice(&data);
                }
                Op::Patch(at, n, b) => {
                    if reference.is_empty() {
                        continue;
                    }
                    let at = (at % reference.len() as u64) as usize;
                    let n = n.min(reference.len() - at);
                    f.seek(SeekFrom::Start(at as u64)).unwrap();
                    let data: Vec<u8> = (0..n).map(|i| b.wrapping_add(i as u8)).collect();
                    // In pieces of 1–8 bytes, as the MCAP writer patches a header field
                    // by field.
                    for piece in data.chunks(1 + b as usize % 8) {
                        f.write_all(piece).unwrap();
                    }
                    reference[at..at + n].copy_from_slice(&data);
                    assert_eq!(f.stream_position().unwrap(), (at + n) as u64);
                }
            }
            if flush_every.is_some_and(|e| k % e == 0) {
                f.flush().unwrap();
            }
        }
        f.flush().unwrap();
        drop(f);
        (std::fs::read(path).unwrap(), reference)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Appends and seeks back anywhere (in the current segment and far behind it),
        /// past the page cache or through it, leave the file equal to the same writes
        /// into a `Vec`.
        #[test]
        fn the_file_holds_what_a_vec_would(
            ops in prop::collection::vec(op(), 1..120),
            flush in prop::option::of(1usize..20),
            direct in any::<bool>(),
        ) {
            let dir = tempdir();
            let path = dir.join("stream.bin");
            let (file, reference) = run(&path, &ops, flush, direct);
            prop_assert_eq!(file.len(), reference.len());
            prop_assert!(file == reference);
            std::fs::remove_dir_all(dir).unwrap();
        }
    }

    /// A directory of its own for each test.
    fn tempdir() -> PathBuf {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let dir = std::env::temp_dir().join(format!(
            "marsupial-uncached-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_seek_past_the_end_is_refused_and_a_short_stream_keeps_its_length() {
        let dir = tempdir();
        let mut f = UncachedFile::create(&dir.join("a.bin")).unwrap();
        f.write_all(b"abc").unwrap();
        assert!(f.seek(SeekFrom::End(1)).is_err());
        assert!(f.seek(SeekFrom::Current(-4)).is_err());
        assert_eq!(f.seek(SeekFrom::Start(1)).unwrap(), 1);
        f.write_all(b"XYZ").unwrap();
        f.flush().unwrap();
        assert_eq!(std::fs::read(dir.join("a.bin")).unwrap(), b"aXYZ");
        drop(f);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
