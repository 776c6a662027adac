//! A structural check of an MCAP file's records before the `mcap` reader parses them:
//! every length-prefixed string a record declares must fit inside that record, and every
//! record inside a chunk must end inside that chunk.
//!
//! Why, both found by fuzzing `Log::from_bytes` (`fuzz/fuzz_targets/replay.rs`):
//! * the reader (`mcap` 0.26, through `binrw`) reserves a string's declared length before
//!   reading it, so a record of a few bytes that declares a 1.3 GB schema name makes it
//!   allocate 1.3 GB. On a robot's computer, where memory is small and overcommit may be
//!   off, that aborts the process;
//! * a record that runs past the end of its uncompressed chunk makes the reader subtract
//!   past zero: a panic with overflow checks on, and with them off a wrapped count that
//!   reads the records after the chunk as if they were inside it;
//! * an attachment record with no room for its CRC after its data length makes the
//!   reader slice out of bounds;
//! * a record whose length is within 9 of `u64::MAX` makes the reader's sum of header and
//!   length overflow.
//!
//! The walk costs one pass over the record headers and no allocation.
//!
//! What is walked, as the reader walks it: the records of the data section from the
//! start magic, the records inside uncompressed chunks, and the summary section the
//! footer points to. Records inside compressed chunks are walked when the replay has
//! decompressed them ([`chunk_flaw`], from [`super::stream`]), before they are parsed. The
//! walk stops quietly at anything it cannot follow (a record that runs past the end of the
//! file, a footer that points nowhere): those are the reader's to report, with the
//! message they come after.

/// MCAP record opcodes (the specification's "Records" section).
mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const CHUNK: u8 = 0x06;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const ATTACHMENT: u8 = 0x09;
    pub const ATTACHMENT_INDEX: u8 = 0x0A;
    pub const METADATA: u8 = 0x0C;
    pub const METADATA_INDEX: u8 = 0x0D;
}

/// The magic at both ends of the file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Magic, then (opcode, length) headers: 1 + 8 bytes.
const MAGIC_LEN: usize = 8;
const RECORD_HEADER: usize = 9;
/// A footer record with its header (1 + 8 + 20) and the end magic.
const FOOTER_AND_MAGIC: usize = RECORD_HEADER + 20 + MAGIC_LEN;

/// A record the `mcap` reader must not be given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flaw {
    /// A string declared longer than the record it is in.
    LongString {
        /// The record's offset in the file, bytes.
        offset: usize,
        /// The record's opcode.
        opcode: u8,
        /// The string's declared length, bytes.
        declared: u32,
        /// What is left of the record after the length prefix, bytes.
        available: usize,
    },
    /// A record too short for the fields after its last string, where the reader slices
    /// without checking (an attachment without room for its CRC).
    ShortRecord {
        /// The record's offset in the file, bytes.
        offset: usize,
        /// The record's opcode.
        opcode: u8,
        /// Bytes missing.
        missing: usize,
    },
    /// A record whose declared length is so large that adding its header's to it
    /// overflows (the reader's sum would wrap).
    HugeRecord {
        /// The record's offset in the file, bytes.
        offset: usize,
        /// Its declared length, bytes.
        declared: u64,
    },
    /// A record inside an uncompressed chunk that runs past the chunk's end (or a tail
    /// too short to be a record header).
    ChunkOverrun {
        /// The chunk's offset in the file, bytes.
        chunk: usize,
        /// The offending record's offset in the file, bytes.
        offset: usize,
    },
}

impl std::fmt::Display for Flaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Flaw::LongString {
                offset,
                opcode,
                declared,
                available,
            } => write!(
                f,
                "the {} record at byte {offset} declares a {declared}-byte string with {available} bytes left in the record",
                record_name(opcode),
            ),
            Flaw::ShortRecord {
                offset,
                opcode,
                missing,
            } => write!(
                f,
                "the {} record at byte {offset} ends {missing} bytes short of its last field",
                record_name(opcode),
            ),
            Flaw::HugeRecord { offset, declared } => write!(
                f,
                "the record at byte {offset} declares a length of {declared} bytes, more than any file holds"
            ),
            Flaw::ChunkOverrun { chunk, offset } => write!(
                f,
                "the record at byte {offset} runs past the end of the chunk at byte {chunk} that holds it"
            ),
        }
    }
}

fn record_name(opcode: u8) -> &'static str {
    match opcode {
        op::HEADER => "header",
        op::SCHEMA => "schema",
        op::CHANNEL => "channel",
        op::CHUNK => "chunk",
        op::CHUNK_INDEX => "chunk index",
        op::ATTACHMENT => "attachment",
        op::ATTACHMENT_INDEX => "attachment index",
        op::METADATA => "metadata",
        op::METADATA_INDEX => "metadata index",
        _ => "unknown",
    }
}

/// The first flaw in the data section (chunks included), else in the summary section.
pub fn first_flaw(bytes: &[u8]) -> Option<Flaw> {
    walk(bytes, MAGIC_LEN, bytes.len(), None).or_else(|| walk(bytes, summary_start(bytes)?, bytes.len(), None))
}

/// The first flaw among the records of a decompressed chunk (`records`, the whole of
/// it): offsets are within `records`.
pub fn chunk_flaw(records: &[u8]) -> Option<Flaw> {
    walk(records, 0, records.len(), Some(0))
}

/// The flaw of the one record `opcode`, `body` at byte `offset`, as [`first_flaw`] finds
/// them (a string declared longer than its record, a record too short for its tail). The
/// replay's stream checks every record with it just before `mcap::parse_record` sees it,
/// whatever the walks above decided to descend into.
pub fn record_flaw(opcode: u8, body: &[u8], offset: usize) -> Option<Flaw> {
    check(opcode, body).err().map(|f| f.at(offset, opcode))
}

/// Where the footer says the summary section starts, as the reader takes it: the last
/// 37 bytes are a footer record (its length field is not read) and the end magic, and a
/// summary start of 0 means none. The reader reads records from there to a footer or
/// the end of the file, wherever "there" is.
fn summary_start(bytes: &[u8]) -> Option<usize> {
    let at = bytes.len().checked_sub(FOOTER_AND_MAGIC)?;
    let footer = &bytes[at..];
    if footer[0] != op::FOOTER || footer[FOOTER_AND_MAGIC - MAGIC_LEN..] != *MAGIC {
        return None;
    }
    let start = usize::try_from(u64_at(footer, RECORD_HEADER)?).ok()?;
    (start != 0 && start < bytes.len()).then_some(start)
}

/// Walks the records from `at` to `end`.
///
/// At the top level (`chunk` is `None`) `end` is where the section ends, and a record
/// that does not fit before it stops the walk quietly (a truncated file, the reader's to
/// report); a chunk is descended into even when the file ends inside it, because the
/// reader streams a chunk's records one by one. Inside the chunk at byte `chunk`, `end`
/// is where the chunk's header says its records end, and a record that does not end by
/// then is a flaw, unless the file ends first.
fn walk(bytes: &[u8], mut at: usize, end: usize, chunk: Option<usize>) -> Option<Flaw> {
    let overrun = |offset| chunk.map(|chunk| Flaw::ChunkOverrun { chunk, offset });
    while at < end {
        let body_at = at + RECORD_HEADER;
        if body_at > end {
            return overrun(at);
        }
        let declared = u64_at(bytes, at + 1)?;
        if declared > (usize::MAX - RECORD_HEADER) as u64 {
            return Some(Flaw::HugeRecord { offset: at, declared });
        }
        let len = usize::try_from(declared).ok();
        let body_end = len.and_then(|len| body_at.checked_add(len)).filter(|&e| e <= end);
        let opcode = bytes[at];
        if chunk.is_none() && opcode == op::CHUNK {
            // The chunk's own string (its compression) is checked below when the chunk is
            // whole; the reader reads a chunk header only from bytes the file has.
            let body = &bytes[body_at..body_end.unwrap_or(usize::MAX).min(bytes.len())];
            if let Some((start, size)) = uncompressed_chunk_records(body, len?) {
                let start = body_at + start;
                if let Some(found) = walk(bytes, start, start + size, Some(at)) {
                    return Some(found);
                }
            }
        }
        let Some(body_end) = body_end else {
            return overrun(at);
        };
        let body = bytes.get(body_at..body_end)?;
        if let Err(fault) = check(opcode, body) {
            return Some(fault.at(at, opcode));
        }
        if opcode == op::FOOTER && chunk.is_none() {
            return None;
        }
        at = body_end;
    }
    None
}

/// Where a chunk stored uncompressed has its records, relative to the start of its
/// `body` (which may be cut short by the end of the file), and how many bytes its header
/// says they take; `None` for a compressed chunk or a header the reader refuses (a
/// compressed size larger than the record of `record_len` bytes).
fn uncompressed_chunk_records(body: &[u8], record_len: usize) -> Option<(usize, usize)> {
    let mut r = Fields::new(body);
    r.skip(8 + 8 + 8 + 4)?;
    if r.u32()? != 0 {
        return None;
    }
    let size = usize::try_from(r.u64()?).ok()?;
    (size <= record_len.checked_sub(r.at)?).then_some((r.at, size))
}

/// One field of a record, as far as the check needs to know it.
#[derive(Clone, Copy)]
enum Field {
    /// Fixed-size fields, bytes.
    Fixed(usize),
    /// A `u32` length and that many bytes of text.
    Str,
    /// A `u32` byte length, then key and value strings.
    StrMap,
    /// A `u32` byte length, then fixed-size entries (no strings).
    FixedMap,
    /// Fixed-size fields after a variable part, which the reader slices to without a
    /// check: the record must have them.
    Tail(usize),
}

/// The fields of each record up to its last string (the specification's layouts).
fn layout(opcode: u8) -> &'static [Field] {
    use Field::{Fixed, FixedMap, Str, StrMap, Tail};
    match opcode {
        op::HEADER => &[Str, Str],
        op::SCHEMA => &[Fixed(2), Str, Str],
        op::CHANNEL => &[Fixed(2 + 2), Str, Str, StrMap],
        op::CHUNK => &[Fixed(8 + 8 + 8 + 4), Str],
        op::CHUNK_INDEX => &[Fixed(8 * 4), FixedMap, Fixed(8), Str],
        op::ATTACHMENT => &[Fixed(8 + 8), Str, Str, Fixed(8), Tail(4)],
        op::ATTACHMENT_INDEX => &[Fixed(8 * 5), Str, Str],
        op::METADATA => &[Str, StrMap],
        op::METADATA_INDEX => &[Fixed(8 + 8), Str],
        _ => &[],
    }
}

/// Checks the strings of one record body; `Ok` also when the body is too short for its
/// fixed fields (the reader reports that, without a large allocation).
fn check(opcode: u8, body: &[u8]) -> Result<(), Fault> {
    let mut r = Fields::new(body);
    for &field in layout(opcode) {
        let more = match field {
            Field::Fixed(n) => r.skip(n).is_some(),
            Field::Str => r.string()?,
            Field::StrMap => r.string_map()?,
            Field::FixedMap => r.u32().and_then(|n| r.skip(n as usize)).is_some(),
            Field::Tail(n) => {
                let left = body.len() - r.at;
                if left < n {
                    return Err(Fault::Short { missing: n - left });
                }
                true
            }
        };
        if !more {
            break;
        }
    }
    Ok(())
}

fn u64_at(bytes: &[u8], at: usize) -> Option<u64> {
    let b = bytes.get(at..at.checked_add(8)?)?;
    Some(u64::from_le_bytes(b.try_into().ok()?))
}

/// What is wrong with one record, before its place in the file is known.
enum Fault {
    /// A string's declared length and the bytes left for it in its record.
    Long { declared: u32, available: usize },
    /// Bytes missing from a [`Field::Tail`].
    Short { missing: usize },
}

impl Fault {
    /// The flaw, in the record at `offset` with `opcode`.
    fn at(self, offset: usize, opcode: u8) -> Flaw {
        match self {
            Fault::Long { declared, available } => Flaw::LongString {
                offset,
                opcode,
                declared,
                available,
            },
            Fault::Short { missing } => Flaw::ShortRecord {
                offset,
                opcode,
                missing,
            },
        }
    }
}

/// A cursor over one record body. A string or map whose length prefix is missing ends
/// the check (`Ok`); one whose declared length overruns the body is the finding.
struct Fields<'a> {
    body: &'a [u8],
    at: usize,
}

impl<'a> Fields<'a> {
    fn new(body: &'a [u8]) -> Self {
        Self { body, at: 0 }
    }

    fn skip(&mut self, n: usize) -> Option<()> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.body.len())?;
        self.at = end;
        Some(())
    }

    fn u32(&mut self) -> Option<u32> {
        let b = self.body.get(self.at..self.at.checked_add(4)?)?;
        self.at += 4;
        Some(u32::from_le_bytes(b.try_into().ok()?))
    }

    fn u64(&mut self) -> Option<u64> {
        let v = u64_at(self.body, self.at)?;
        self.at += 8;
        Some(v)
    }

    /// A `u32` length and that many bytes. `Err` when the length overruns the body;
    /// `Ok(false)` when there is no length to read (the walk of this record stops).
    fn string(&mut self) -> Result<bool, Fault> {
        let Some(declared) = self.u32() else {
            return Ok(false);
        };
        let available = self.body.len() - self.at;
        if declared as usize > available {
            return Err(Fault::Long { declared, available });
        }
        self.at += declared as usize;
        Ok(true)
    }

    /// A `u32` byte length, then key and value strings until that many bytes are used,
    /// as the reader parses it. `Ok(false)` when the map stops short.
    fn string_map(&mut self) -> Result<bool, Fault> {
        let Some(byte_len) = self.u32() else {
            return Ok(false);
        };
        let start = self.at;
        while self.at - start < byte_len as usize {
            if !self.string()? || !self.string()? {
                return Ok(false);
            }
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A small but complete log: header, schema, channel with metadata, messages,
    /// metadata and attachment records, and a summary (with chunk indexes when chunked).
    fn log(chunked: bool) -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .use_chunks(chunked)
            .compression(None)
            .create(&mut out)
            .unwrap();
        let schema = w.add_schema("pkg/msg/Thing", "ros2msg", b"float64 x\n").unwrap();
        let meta = BTreeMap::from([("qos".to_string(), "depth: 1".to_string())]);
        let channel = w.add_channel(schema, "/thing", "cdr", &meta).unwrap();
        for k in 0..3u32 {
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: k,
                log_time: u64::from(k) * 10,
                publish_time: u64::from(k) * 10,
            };
            w.write_to_known_channel(&header, &[1, 2, 3, k as u8]).unwrap();
        }
        w.write_metadata(&mcap::records::Metadata {
            name: "robot".into(),
            metadata: BTreeMap::from([("name".to_string(), "bujold".to_string())]),
        })
        .unwrap();
        w.attach(&mcap::Attachment {
            log_time: 1,
            create_time: 2,
            name: "calibration".into(),
            media_type: "text/plain".into(),
            data: std::borrow::Cow::Borrowed(b"fx 400"),
        })
        .unwrap();
        w.finish().unwrap();
        drop(w);
        out.into_inner()
    }

    /// Offsets of every occurrence of `needle`.
    fn find_all(hay: &[u8], needle: &[u8]) -> Vec<usize> {
        (0..=hay.len() - needle.len())
            .filter(|&i| &hay[i..i + needle.len()] == needle)
            .collect()
    }

    fn set_u32(bytes: &mut [u8], at: usize, v: u32) {
        bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
    }

    #[test]
    fn well_formed_logs_have_no_flaw() {
        for chunked in [false, true] {
            let bytes = log(chunked);
            assert_eq!(first_flaw(&bytes), None, "chunked {chunked}");
            // And the reader agrees they are whole.
            let n = mcap::MessageStream::new(&bytes).unwrap().count();
            assert_eq!(n, 3);
            // Every prefix (a truncated file) is the reader's to report, not a flaw.
            for cut in 0..bytes.len() {
                assert_eq!(first_flaw(&bytes[..cut]), None, "chunked {chunked}, cut {cut}");
            }
        }
    }

    #[test]
    fn an_overlong_string_is_found_in_every_place_the_reader_would_reserve_it() {
        // A string in the log, and the records that may hold it.
        let strings: [(&[u8], &[u8]); 7] = [
            (b"ros2", &[op::HEADER]),
            (b"pkg/msg/Thing", &[op::SCHEMA]),
            (b"/thing", &[op::CHANNEL]),
            (b"depth: 1", &[op::CHANNEL]),
            (b"bujold", &[op::METADATA]),
            (b"text/plain", &[op::ATTACHMENT, op::ATTACHMENT_INDEX]),
            (b"calibration", &[op::ATTACHMENT, op::ATTACHMENT_INDEX]),
        ];
        for chunked in [false, true] {
            let good = log(chunked);
            for (text, holders) in strings {
                // Each copy of the string (the data section's, the summary's) on its own;
                // a copy is where the length prefix before it is the string's length.
                let copies: Vec<usize> = find_all(&good, text)
                    .into_iter()
                    .filter(|&at| at >= 4 && good[at - 4..at] == (text.len() as u32).to_le_bytes())
                    .collect();
                assert!(!copies.is_empty());
                for at in copies {
                    let mut bad = good.clone();
                    set_u32(&mut bad, at - 4, 1_347_440_720);
                    let what = format!("{} at {at} (chunked {chunked})", String::from_utf8_lossy(text));
                    let flaw = first_flaw(&bad).unwrap_or_else(|| panic!("{what}: not found"));
                    let Flaw::LongString {
                        offset,
                        opcode,
                        declared,
                        available,
                    } = flaw
                    else {
                        panic!("{what}: {flaw:?}");
                    };
                    assert_eq!(declared, 1_347_440_720);
                    assert!(available < 200, "{what}: {available}");
                    assert!(offset < at && bad[offset] == opcode, "{what}: {flaw:?}");
                    assert!(holders.contains(&opcode), "{what}: {flaw:?}");
                    assert!(flaw.to_string().contains("1347440720-byte string"));
                    // Also when the file ends just after that record, inside its chunk:
                    // the reader streams a chunk's records, so it would still parse it.
                    let record_end = offset + RECORD_HEADER + u64_at(&bad, offset + 1).unwrap() as usize;
                    assert_eq!(first_flaw(&bad[..record_end]), Some(flaw), "{what}, cut");
                }
            }
        }
    }

    #[test]
    fn the_summary_is_walked_wherever_the_footer_points_whatever_its_length_field_says() {
        let mut bad = log(false);
        let n = bad.len();
        let footer = n - FOOTER_AND_MAGIC;
        // The reader takes the footer's body as 20 bytes whatever its length field says.
        bad[footer + 1..footer + 9].copy_from_slice(&0x0100_0000_0000_0014u64.to_le_bytes());
        let summary_copy = *find_all(&bad, b"/thing").last().unwrap();
        assert!(summary_copy > u64_at(&bad, footer + RECORD_HEADER).unwrap() as usize);
        set_u32(&mut bad, summary_copy - 4, 0x7000_0000);
        assert!(matches!(
            first_flaw(&bad),
            Some(Flaw::LongString {
                opcode: op::CHANNEL,
                ..
            })
        ));
    }

    #[test]
    fn an_attachment_needs_room_for_its_crc() {
        let mut body = Vec::new();
        body.extend_from_slice(&[0; 16]); // log and create times
        for text in [b"a", b"b"] {
            body.extend_from_slice(&1u32.to_le_bytes());
            body.extend_from_slice(text);
        }
        body.extend_from_slice(&0u64.to_le_bytes()); // data length
        for crc_bytes in 0..4 {
            let mut short = body.clone();
            short.extend(std::iter::repeat_n(0, crc_bytes));
            assert!(matches!(
                check(op::ATTACHMENT, &short),
                Err(Fault::Short { missing }) if missing == 4 - crc_bytes
            ));
        }
        body.extend_from_slice(&[0; 4]);
        assert!(check(op::ATTACHMENT, &body).is_ok());
        // Cut inside the fixed fields, the reader's own parse fails first: not a flaw.
        assert!(check(op::ATTACHMENT, &body[..12]).is_ok());
    }

    #[test]
    fn a_record_running_past_its_chunk_is_found() {
        let good = log(true);
        // The first message record inside the chunk: opcode 0x05, then its length (the
        // 22-byte message header and 4 bytes of data).
        let message = find_all(&good, &[0x05, 26, 0, 0, 0, 0, 0, 0, 0])[0];
        for len in [27 + (1 << 20), u64::MAX - 9] {
            let mut bad = good.clone();
            bad[message + 1..message + 9].copy_from_slice(&len.to_le_bytes());
            match first_flaw(&bad) {
                Some(Flaw::ChunkOverrun { chunk, offset }) => {
                    assert_eq!(offset, message);
                    assert!(chunk < message && bad[chunk] == op::CHUNK);
                }
                other => panic!("length {len}: {other:?}"),
            }
        }
    }

    #[test]
    fn a_length_the_reader_would_overflow_on_is_found_anywhere() {
        for chunked in [false, true] {
            let good = log(chunked);
            let message = find_all(&good, &[0x05, 26, 0, 0, 0, 0, 0, 0, 0])[0];
            for len in [u64::MAX - 8, u64::MAX] {
                let mut bad = good.clone();
                bad[message + 1..message + 9].copy_from_slice(&len.to_le_bytes());
                assert_eq!(
                    first_flaw(&bad),
                    Some(Flaw::HugeRecord {
                        offset: message,
                        declared: len
                    }),
                    "chunked {chunked}"
                );
            }
        }
    }
}
