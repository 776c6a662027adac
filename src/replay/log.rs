//! Reading an MCAP log: its topics, then its messages in file order, each numbered within
//! its topic so errors can name it (`/camera/image_raw` message #12).
//!
//! A log is one MCAP file, or a rosbag2 directory (its `metadata.yaml` and the split
//! files it names, read in its order as one log: [`super::bag_dir`]). Each file is mapped
//! into memory; its messages are read by [`super::stream`], which decodes zstd and lz4
//! chunks in the default build. A file that ends early (a robot that lost power while recording) gives every message
//! before the cut, then [`ReplayError::Log`] with [`LogFault::Truncated`]. A record that
//! declares a string longer than itself is refused before the reader sees the file
//! ([`super::preflight`]), wherever it is.

use super::ReplayError;
use super::stream::{Fault, Stream};
use super::topics::{TopicInfo, Topics};
use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// What is wrong with the file itself (not with one message in it).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LogFault {
    /// Not an MCAP file (no magic at the start).
    #[error("not an MCAP file ({why})")]
    NotMcap {
        /// The reader's message.
        why: String,
    },
    /// The file ends inside a record.
    #[error("the file is truncated: it ends inside a record{}", after_text(after))]
    Truncated {
        /// The last message read before the cut (topic, index), if any.
        after: Option<(String, u64)>,
    },
    /// Chunks compressed with a codec no MCAP writer is known to use (zstd, lz4 and
    /// uncompressed chunks are read).
    #[error(
        "chunks compressed with `{compression}` cannot be read (the first comes{}): only zstd, lz4 and uncompressed chunks are; re-write the log (`mcap convert`, `ros2 bag convert`)",
        after_text(after)
    )]
    Compression {
        /// The chunk compression.
        compression: String,
        /// The last message read before it, if any.
        after: Option<(String, u64)>,
    },
    /// A record the reader must not be given (a string longer than its record, a record
    /// running past its chunk), found before reading anything.
    #[error("malformed file: {0}")]
    Malformed(super::preflight::Flaw),
    /// As [`LogFault::Malformed`], in the records of a compressed chunk, found once it
    /// is decompressed.
    #[error("malformed file: in the compressed chunk at byte {chunk}, once decompressed, {flaw}")]
    MalformedChunk {
        /// The chunk's offset in the file, bytes.
        chunk: usize,
        /// The flaw (its offset is within the decompressed records).
        flaw: super::preflight::Flaw,
    },
    /// Any other malformed record.
    #[error("malformed record{}: {why}", after_text(after))]
    Corrupt {
        /// The reader's message.
        why: String,
        /// The last message read before it, if any.
        after: Option<(String, u64)>,
    },
}

fn after_text(after: &Option<(String, u64)>) -> String {
    match after {
        Some((t, i)) => format!(" after message #{i} of `{t}`"),
        None => " before the first message".into(),
    }
}

/// Runs a call into the `mcap` reader, turning a panic inside it into
/// [`LogFault::Corrupt`]: the reader (0.26) has arithmetic that overflows on some
/// malformed records (found by fuzzing, `fuzz/fuzz_targets/replay.rs`), and a malformed
/// file must give an error naming where it broke, never a panic.
fn contained<T>(after: &Option<(String, u64)>, f: impl FnOnce() -> T) -> Result<T, LogFault> {
    crate::panics::contain("the MCAP reader failed", f).map_err(|why| LogFault::Corrupt {
        why: format!("the MCAP reader gave up on it ({why})"),
        after: after.clone(),
    })
}

fn fault(e: Fault, after: Option<(String, u64)>) -> LogFault {
    let e = match e {
        Fault::Mcap(e) => e,
        Fault::Flaw { chunk, flaw } => return LogFault::MalformedChunk { chunk, flaw },
        Fault::Record(flaw) => return LogFault::Malformed(flaw),
    };
    match e {
        mcap::McapError::UnexpectedEof | mcap::McapError::BadFooter => LogFault::Truncated { after },
        mcap::McapError::UnsupportedCompression(compression) => LogFault::Compression { compression, after },
        mcap::McapError::BadMagic if after.is_none() => LogFault::NotMcap { why: e.to_string() },
        e => LogFault::Corrupt {
            why: e.to_string(),
            after,
        },
    }
}

/// One message of a topic being read.
#[derive(Debug)]
pub struct LogMessage<'a> {
    /// Its topic.
    pub topic: &'a str,
    /// Its index within the topic, from 0.
    pub index: u64,
    /// Log time, ns.
    pub log_time: u64,
    /// The serialised message.
    pub data: Cow<'a, [u8]>,
}

/// A log's bytes: its file mapped into memory, or bytes handed in.
///
/// A mapped file is read page by page as the replay reaches it, and the kernel may drop
/// pages already read, so a bag larger than the memory replays; it is never copied.
enum LogBytes {
    Mapped(memmap2::Mmap),
    Owned(Vec<u8>),
}

impl std::ops::Deref for LogBytes {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        match self {
            LogBytes::Mapped(m) => m,
            LogBytes::Owned(v) => v,
        }
    }
}

/// One MCAP file of a log, mapped into memory.
struct Part {
    path: PathBuf,
    bytes: LogBytes,
}

/// An MCAP log (one file, or a rosbag2 directory's split files), mapped into memory,
/// with its topics.
pub struct Log {
    path: PathBuf,
    parts: Vec<Part>,
    topics: Topics,
}

impl Log {
    /// Reads `path`, an MCAP file or a rosbag2 directory, and lists its topics (from each
    /// file's summary, or by reading the file through when it has none, as a truncated
    /// file has not).
    ///
    /// Each file is mapped into memory, not read: a log of any size opens at once and
    /// costs only the pages the replay touches (a pipe, which cannot be mapped, is read).
    /// It must not shrink while it is replayed (a log another program is still cutting or
    /// rotating): reading a page that a truncation took away ends the process with
    /// `SIGBUS`, as it would for any reader that maps files.
    ///
    /// # Errors
    /// [`ReplayError::Io`], [`ReplayError::Bag`] for a directory whose `metadata.yaml` is
    /// missing, malformed or names a file that is not there, or [`ReplayError::Log`] when
    /// a file is not MCAP.
    pub fn open(path: &Path) -> Result<Self, ReplayError> {
        if path.is_dir() {
            let files = super::bag_dir::split_files(path)?;
            let parts = files.iter().map(|f| open_part(f)).collect::<Result<Vec<_>, _>>()?;
            return Self::from_parts(path, parts);
        }
        Self::from_parts(path, vec![open_part(path)?])
    }

    /// As [`Log::open`], for bytes already in memory (`path` names them in errors).
    ///
    /// # Errors
    /// [`ReplayError::Log`] when the bytes are not MCAP.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, ReplayError> {
        let part = Part {
            path: path.to_path_buf(),
            bytes: LogBytes::Owned(bytes),
        };
        Self::from_parts(path, vec![part])
    }

    fn from_parts(path: &Path, parts: Vec<Part>) -> Result<Self, ReplayError> {
        let mut topics = Topics::new();
        for part in &parts {
            part_topics(part, &mut topics)?;
        }
        Ok(Self {
            path: path.to_path_buf(),
            parts,
            topics,
        })
    }

    /// The log's file or directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The log's topics.
    pub fn topics(&self) -> &Topics {
        &self.topics
    }

    /// The messages of `wanted` topics in file order (file after file); a fault in a file
    /// ends the iteration with one [`ReplayError::Log`] naming that file. A topic's
    /// messages are numbered across the files.
    pub fn messages<'a>(&'a self, wanted: &[&str]) -> Messages<'a> {
        Messages {
            log: self,
            part: 0,
            stream: self.parts.first().map(|p| Stream::new(&p.bytes)),
            wanted: wanted.iter().map(|s| s.to_string()).collect(),
            counts: BTreeMap::new(),
            last: None,
        }
    }
}

/// Maps (or, for a pipe, reads) one file.
fn open_part(path: &Path) -> Result<Part, ReplayError> {
    let io = |source| ReplayError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    let bytes = if !meta.is_file() || meta.len() == 0 {
        // A pipe cannot be mapped, so it is read (and a directory is refused by the read,
        // by name).
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut file, &mut bytes).map_err(io)?;
        LogBytes::Owned(bytes)
    } else {
        // SAFETY: the map is read-only and lives as long as `Log`. That its bytes do not
        // change holds only while no other program writes to or truncates the file; the
        // doc of `Log::open` makes that the caller's condition, as every reader that maps
        // logs does.
        LogBytes::Mapped(unsafe { memmap2::Mmap::map(&file) }.map_err(io)?)
    };
    Ok(Part {
        path: path.to_path_buf(),
        bytes,
    })
}

/// Checks one file (magic, preflight) and adds its topics.
fn part_topics(part: &Part, topics: &mut Topics) -> Result<(), ReplayError> {
    let log_err = |fault| ReplayError::Log {
        path: part.path.clone(),
        fault,
    };
    let bytes = &part.bytes[..];
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(log_err(LogFault::NotMcap {
            why: "no MCAP magic at the start".into(),
        }));
    }
    if let Some(flaw) = super::preflight::first_flaw(bytes) {
        return Err(log_err(LogFault::Malformed(flaw)));
    }
    let mut add = |c: &mcap::Channel<'_>| {
        topics.entry(c.topic.clone()).or_insert_with(|| TopicInfo {
            topic: c.topic.clone(),
            schema: c.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default(),
            encoding: c.message_encoding.clone(),
        });
    };
    match contained(&None, || mcap::Summary::read(bytes)).map_err(log_err)? {
        Ok(Some(s)) if !s.channels.is_empty() => {
            let sorted: BTreeMap<_, _> = s.channels.iter().collect();
            sorted.values().for_each(|c| add(c));
        }
        _ => {
            // No summary: walk the messages (stopping quietly at a fault, which the
            // replay itself reports with its position).
            let mut stream = Stream::new(bytes);
            while let Ok(Some(Ok(m))) = contained(&None, || stream.next()) {
                add(&m.channel);
            }
        }
    }
    Ok(())
}

/// Iterator of [`Log::messages`].
pub struct Messages<'a> {
    log: &'a Log,
    part: usize,
    /// The current file's messages; `None` once the iteration has ended.
    stream: Option<Stream<'a>>,
    wanted: BTreeSet<String>,
    counts: BTreeMap<String, u64>,
    last: Option<(String, u64)>,
}

impl<'a> Iterator for Messages<'a> {
    type Item = Result<LogMessage<'a>, ReplayError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let stream = self.stream.as_mut()?;
            let path = &self.log.parts[self.part].path;
            let err = |fault| {
                Some(Err(ReplayError::Log {
                    path: path.clone(),
                    fault,
                }))
            };
            let next = match contained(&self.last, || stream.next()) {
                Ok(next) => next,
                Err(f) => {
                    self.stream = None;
                    return err(f);
                }
            };
            match next {
                None => {
                    self.part += 1;
                    self.stream = self.log.parts.get(self.part).map(|p| Stream::new(&p.bytes));
                }
                Some(Err(e)) => {
                    self.stream = None;
                    return err(fault(e, self.last.take()));
                }
                Some(Ok(m)) => {
                    let Some(topic) = self.wanted.get(m.channel.topic.as_str()) else {
                        continue;
                    };
                    let n = self.counts.entry(topic.clone()).or_insert(0);
                    let index = *n;
                    *n += 1;
                    self.last = Some((topic.clone(), index));
                    let topic: &'a str = self
                        .log
                        .topics
                        .get_key_value(topic.as_str())
                        .map(|(k, _)| k.as_str())
                        .unwrap_or("");
                    return Some(Ok(LogMessage {
                        topic,
                        index,
                        log_time: m.log_time,
                        data: m.data,
                    }));
                }
            }
        }
    }
}
