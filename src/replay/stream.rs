//! The messages of one MCAP file in file order, linked to their channels.
//!
//! Why not `mcap::MessageStream`: the `mcap` crate decodes zstd and lz4 chunks only with
//! its C libraries, and libmcap's writer (rosbag2's MCAP storage) and Foxglove compress
//! chunks with zstd by default, so a user's bag must be decoded in the default build.
//! Here chunks are decoded by pure-Rust decoders (`ruzstd`, `lz4_flex`) into one buffer
//! reused from chunk to chunk; the records they hold get the same structural check as the
//! file's own ([`super::preflight::chunk_flaw`]) before `mcap::parse_record` sees them,
//! and a chunk's CRC, when it has one, is checked. Records and uncompressed chunks are
//! read in place from the file's bytes (the message data of a compressed chunk is copied
//! out of the buffer, as `mcap`'s reader copies every message).
//!
//! A file that ends early gives every message before the cut, then
//! [`McapError::UnexpectedEof`]; the records of an uncompressed chunk cut short are still
//! given, a compressed chunk cut short is not decoded.

use super::preflight::{self, Flaw};
use mcap::McapError;
use mcap::records::{Record, op};
use std::borrow::Cow;
use std::io::Read;
use std::sync::Arc;

/// Opcode and length, bytes.
const RECORD_HEADER: usize = 9;
/// A chunk's fixed fields before its compression string, bytes.
const CHUNK_FIXED: usize = 8 + 8 + 8 + 4 + 4;

/// Why the stream stopped.
#[derive(Debug)]
pub enum Fault {
    /// What the `mcap` reader would say (truncation, an unknown channel, a bad chunk).
    Mcap(McapError),
    /// A record inside the decompressed chunk at byte `chunk` the reader must not see.
    Flaw {
        /// The chunk's offset in the file, bytes.
        chunk: usize,
        /// The flaw; its offset is within the decompressed records.
        flaw: Flaw,
    },
    /// A record, outside a decompressed chunk, the reader must not see (its offset is in
    /// the file).
    Record(Flaw),
}

impl From<McapError> for Fault {
    fn from(e: McapError) -> Self {
        Fault::Mcap(e)
    }
}

/// One message, linked to its channel.
pub struct RawMessage<'a> {
    /// Its channel (with topic and schema).
    pub channel: Arc<mcap::Channel<'static>>,
    /// Log time, ns.
    pub log_time: u64,
    /// The serialised message: in the file, or copied out of a decompressed chunk.
    pub data: Cow<'a, [u8]>,
}

/// Where the chunk being read has its records.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Source {
    /// In the file (an uncompressed chunk).
    File,
    /// In [`Stream::scratch`] (a decompressed chunk).
    Scratch,
}

/// The chunk being read: its records are `at..end` of its source.
struct Chunk {
    source: Source,
    /// The chunk record's offset in the file, bytes.
    chunk: usize,
    at: usize,
    end: usize,
    /// The file ends inside it (`end` is the end of the file).
    cut: bool,
}

/// Iterator of the messages of one MCAP file (its magic already checked by the caller).
pub struct Stream<'a> {
    bytes: &'a [u8],
    at: usize,
    chunk: Option<Chunk>,
    scratch: Vec<u8>,
    zstd: ruzstd::decoding::FrameDecoder,
    channels: mcap::read::ChannelAccumulator<'static>,
    /// After the data end record: the summary repeats schemas and channels, which are
    /// not linked again (as `mcap`'s reader does not).
    past_data_end: bool,
    done: bool,
}

impl<'a> Stream<'a> {
    /// The messages of the file `bytes`, from the record after the start magic.
    pub fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            at: mcap::MAGIC.len(),
            chunk: None,
            scratch: Vec::new(),
            zstd: ruzstd::decoding::FrameDecoder::new(),
            channels: Default::default(),
            past_data_end: false,
            done: false,
        }
    }

    fn advance(&mut self) -> Result<Option<RawMessage<'a>>, Fault> {
        loop {
            if let Some(c) = &mut self.chunk {
                if c.at >= c.end {
                    let cut = c.cut;
                    self.chunk = None;
                    if cut {
                        return Err(McapError::UnexpectedEof.into());
                    }
                    continue;
                }
                // A record of an uncompressed chunk borrows the file; one of a decompressed
                // chunk is copied out of the buffer the next chunk reuses.
                let found = if c.source == Source::File {
                    next_in_chunk(self.bytes, c, &mut self.channels)?.map(|(ch, t, d)| (ch, t, Cow::Borrowed(d)))
                } else {
                    next_in_chunk(&self.scratch, c, &mut self.channels)?
                        .map(|(ch, t, d)| (ch, t, Cow::Owned(d.to_vec())))
                };
                if let Some((channel, log_time, data)) = found {
                    return Ok(Some(RawMessage {
                        channel,
                        log_time,
                        data,
                    }));
                }
                continue;
            }
            let bytes = self.bytes;
            let Some((opcode, body_at, len)) = header_at(bytes, self.at) else {
                return Err(McapError::UnexpectedEof.into());
            };
            let body_end = body_at.checked_add(len).filter(|&e| e <= bytes.len());
            if opcode == op::CHUNK && !self.past_data_end {
                self.open_chunk(body_at, body_end)?;
                self.at = body_end.unwrap_or(bytes.len());
                continue;
            }
            let Some(body_end) = body_end else {
                return Err(McapError::UnexpectedEof.into());
            };
            if opcode == op::FOOTER {
                let tail = &bytes[body_end..];
                return if tail.starts_with(mcap::MAGIC) {
                    Ok(None)
                } else if mcap::MAGIC.starts_with(tail) {
                    Err(McapError::UnexpectedEof.into())
                } else {
                    Err(McapError::BadMagic.into())
                };
            }
            self.at = body_end;
            if opcode == op::DATA_END {
                self.past_data_end = true;
            }
            if self.past_data_end {
                continue;
            }
            let body = &bytes[body_at..body_end];
            if let Some(flaw) = preflight::record_flaw(opcode, body, body_at - RECORD_HEADER) {
                return Err(Fault::Record(flaw));
            }
            if let Some((channel, log_time, data)) = link(&mut self.channels, opcode, body)? {
                return Ok(Some(RawMessage {
                    channel,
                    log_time,
                    data: Cow::Borrowed(data),
                }));
            }
        }
    }

    /// Starts reading the chunk whose body starts at `body_at` (and ends at `body_end`,
    /// `None` when the file ends first).
    fn open_chunk(&mut self, body_at: usize, body_end: Option<usize>) -> Result<(), Fault> {
        let chunk_at = self.at;
        let bytes = self.bytes;
        let body = &bytes[body_at..body_end.unwrap_or(bytes.len())];
        let short = || match body_end {
            Some(_) => McapError::UnexpectedEoc,
            None => McapError::UnexpectedEof,
        };
        let field = |at: usize, n: usize| body.get(at..at + n).ok_or_else(short);
        let u64_at = |at| field(at, 8).map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()));
        let size = u64_at(16)?;
        let crc = u32::from_le_bytes(field(24, 4)?.try_into().unwrap_or_default());
        let name_len = u32::from_le_bytes(field(28, 4)?.try_into().unwrap_or_default()) as usize;
        let name = field(CHUNK_FIXED, name_len)?;
        let data_at = CHUNK_FIXED + name_len + 8;
        let compressed = u64_at(CHUNK_FIXED + name_len)?;
        let data_end = usize::try_from(compressed).ok().and_then(|n| data_at.checked_add(n));
        let data = match data_end {
            Some(end) if end <= body.len() => &body[data_at..end],
            _ if body_end.is_some() => {
                let available = (body.len() - data_at.min(body.len())) as u64;
                return Err(McapError::BadChunkLength {
                    header: compressed,
                    available,
                }
                .into());
            }
            // The file ends inside the chunk's data: what there is of an uncompressed chunk
            // is read; a compressed one cannot be decoded.
            _ if name.is_empty() => &body[data_at.min(body.len())..],
            _ => return Err(McapError::UnexpectedEof.into()),
        };
        let cut = body_end.is_none();
        if name.is_empty() {
            let at = body_at + data_at.min(body.len());
            self.chunk = Some(Chunk {
                source: Source::File,
                chunk: chunk_at,
                at,
                end: at + data.len(),
                cut,
            });
            return Ok(());
        }
        let name = String::from_utf8_lossy(name);
        decompress(&name, data, size, &mut self.scratch, &mut self.zstd)?;
        if crc != 0 {
            let calculated = crc32fast::hash(&self.scratch);
            if calculated != crc {
                return Err(McapError::BadChunkCrc { saved: crc, calculated }.into());
            }
        }
        if let Some(flaw) = preflight::chunk_flaw(&self.scratch) {
            return Err(Fault::Flaw { chunk: chunk_at, flaw });
        }
        self.chunk = Some(Chunk {
            source: Source::Scratch,
            chunk: chunk_at,
            at: 0,
            end: self.scratch.len(),
            cut,
        });
        Ok(())
    }
}

impl<'a> Iterator for Stream<'a> {
    type Item = Result<RawMessage<'a>, Fault>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let next = self.advance();
        self.done = !matches!(next, Ok(Some(_)));
        next.transpose()
    }
}

/// The opcode, body offset and body length of the record at `at`; `None` when the bytes
/// end before its header does.
fn header_at(bytes: &[u8], at: usize) -> Option<(u8, usize, usize)> {
    let header = bytes.get(at..at.checked_add(RECORD_HEADER)?)?;
    let len = u64::from_le_bytes(header[1..].try_into().ok()?);
    Some((
        header[0],
        at + RECORD_HEADER,
        usize::try_from(len).unwrap_or(usize::MAX),
    ))
}

/// A linked message: channel, log time, data.
type Linked<'b> = (Arc<mcap::Channel<'static>>, u64, &'b [u8]);

/// Reads the next record of chunk `c` from `records`, linking it.
fn next_in_chunk<'b>(
    records: &'b [u8],
    c: &mut Chunk,
    channels: &mut mcap::read::ChannelAccumulator<'static>,
) -> Result<Option<Linked<'b>>, Fault> {
    let body = header_at(records, c.at).and_then(|(opcode, body_at, len)| {
        let end = body_at.checked_add(len).filter(|&e| e <= c.end)?;
        Some((opcode, body_at, end))
    });
    let Some((opcode, body_at, end)) = body else {
        // The preflight refuses a record running past its chunk, so only a cut file
        // leaves one here.
        c.at = c.end;
        return Err(if c.cut {
            McapError::UnexpectedEof
        } else {
            McapError::UnexpectedEoc
        }
        .into());
    };
    c.at = end;
    let body = &records[body_at..end];
    if let Some(flaw) = preflight::record_flaw(opcode, body, body_at - RECORD_HEADER) {
        return Err(match c.source {
            Source::File => Fault::Record(flaw),
            Source::Scratch => Fault::Flaw { chunk: c.chunk, flaw },
        });
    }
    Ok(link(channels, opcode, body)?)
}

/// Records a schema or channel; gives a message linked to its channel.
fn link<'b>(
    channels: &mut mcap::read::ChannelAccumulator<'static>,
    opcode: u8,
    body: &'b [u8],
) -> Result<Option<Linked<'b>>, McapError> {
    match opcode {
        op::SCHEMA | op::CHANNEL | op::MESSAGE => {}
        _ => return Ok(None),
    }
    match mcap::parse_record(opcode, body)? {
        Record::Schema { header, data } => channels.add_schema_from_slice(header, data.as_ref())?,
        Record::Channel(c) => channels.add_channel(c)?,
        Record::Message { header, data } => {
            let channel = channels
                .get(header.channel_id)
                .ok_or(McapError::UnknownChannel(header.sequence, header.channel_id))?;
            // The data is the body after the message's fixed fields.
            let data = &body[body.len() - data.len()..];
            return Ok(Some((channel, header.log_time, data)));
        }
        _ => {}
    }
    Ok(None)
}

/// Decompresses a chunk's `data` into `out` (cleared first, its capacity kept), which
/// must then hold exactly the `size` bytes the chunk's header declares. The buffer grows
/// with what the decoder gives, never to a declared size it does not reach.
fn decompress(
    name: &str,
    mut data: &[u8],
    size: u64,
    out: &mut Vec<u8>,
    zstd: &mut ruzstd::decoding::FrameDecoder,
) -> Result<(), McapError> {
    let bad = |why: String| McapError::DecompressionError(format!("{name} chunk: {why}"));
    out.clear();
    match name {
        "zstd" => {
            // A chunk may hold several frames, and skippable ones.
            while (out.len() as u64) < size && !data.is_empty() {
                use ruzstd::decoding::errors::{FrameDecoderError, ReadFrameHeaderError};
                match ruzstd::decoding::StreamingDecoder::new_with_decoder(&mut data, &mut *zstd) {
                    Ok(mut frame) => {
                        let left = size - out.len() as u64;
                        (&mut frame)
                            .take(left)
                            .read_to_end(out)
                            .map_err(|e| bad(e.to_string()))?;
                        let d = frame.decoder;
                        if let (Some(saved), Some(calculated)) =
                            (d.get_checksum_from_data(), d.get_calculated_checksum())
                            && d.is_finished()
                            && saved != calculated
                        {
                            return Err(bad(format!(
                                "frame checksum {saved:#010x}, calculated {calculated:#010x}"
                            )));
                        }
                    }
                    Err(FrameDecoderError::ReadFrameHeaderError(ReadFrameHeaderError::SkipFrame {
                        length, ..
                    })) => {
                        data = data.get(length as usize..).unwrap_or_default();
                    }
                    Err(e) => return Err(bad(e.to_string())),
                }
            }
        }
        "lz4" => {
            lz4_flex::frame::FrameDecoder::new(data)
                .take(size)
                .read_to_end(out)
                .map_err(|e| bad(e.to_string()))?;
        }
        other => return Err(McapError::UnsupportedCompression(other.into())),
    }
    if out.len() as u64 != size {
        return Err(bad(format!(
            "it decodes to {} bytes, its header says {size}",
            out.len()
        )));
    }
    Ok(())
}
