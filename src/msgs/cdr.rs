//! CDR (OMG XCDR version 1, "plain CDR"): [`CdrReader`] and [`CdrWriter`], which the
//! bridge's messages are written with, and decoding of the three ROS 2 messages the bridge
//! and a replay read: `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage` and
//! `nav_msgs/msg/Odometry`, as rosbag2 stores them in MCAP (message encoding `cdr`).
//!
//! A serialised message starts with a 4-byte encapsulation header: two bytes of
//! representation identifier, big-endian (`00 00` CDR big-endian, `00 01` CDR
//! little-endian; every other identifier, XCDR2 and parameter lists included, is refused),
//! and two bytes of options, ignored. The body follows, every primitive aligned to its own
//! size (8 for `float64`), counted from the first byte *after* the header. A `string` is a
//! `uint32` length that counts the terminating NUL, the bytes, then the NUL; a sequence
//! (`uint8[]`) is a `uint32` element count then the elements; a fixed array
//! (`float64[36]`) is its elements alone.
//!
//! The functions here are pure, over `&[u8]`, and never panic: every read is bounds
//! checked, so they can be fuzzed directly.

use super::ros::{CompressedImage, Header, Image, Odometry, Time};
use thiserror::Error;

/// Why a CDR message did not decode; `offset` is a byte offset in the whole message
/// (header included), where the failing field starts.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CdrError {
    /// Fewer than 4 bytes: no encapsulation header.
    #[error("{len} bytes: too short for the 4-byte CDR encapsulation header")]
    NoHeader {
        /// The message's length.
        len: usize,
    },
    /// An encapsulation this decoder does not read (only plain CDR, XCDR1, is).
    #[error("encapsulation 0x{id:04x} is not plain CDR (expected 0x0000 big-endian or 0x0001 little-endian)")]
    Encapsulation {
        /// The representation identifier.
        id: u16,
    },
    /// The message ends inside a field.
    #[error("truncated at byte {offset}: {field} needs {need} bytes, {left} left")]
    Truncated {
        /// Where the field starts.
        offset: usize,
        /// The field being read.
        field: &'static str,
        /// Bytes it needs.
        need: usize,
        /// Bytes left in the message.
        left: usize,
    },
    /// A string whose length is 0 (it must count its NUL) or whose last byte is not NUL.
    #[error("byte {offset}: string `{field}` is not NUL-terminated (length {len})")]
    StringTerminator {
        /// Where the string's length starts.
        offset: usize,
        /// The field.
        field: &'static str,
        /// Its declared length.
        len: u32,
    },
    /// A string that is not UTF-8.
    #[error("byte {offset}: string `{field}` is not UTF-8")]
    StringUtf8 {
        /// Where the string's bytes start.
        offset: usize,
        /// The field.
        field: &'static str,
    },
}

/// Byte order of a CDR body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Order {
    Big,
    Little,
}

/// A cursor over one CDR message (see the module docs for the layout it reads).
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    /// Position in `buf`; the body starts at 4.
    pos: usize,
    order: Order,
}

impl<'a> CdrReader<'a> {
    /// Reads the encapsulation header of `buf` and stands at the body's first byte.
    ///
    /// # Errors
    /// [`CdrError::NoHeader`], [`CdrError::Encapsulation`].
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        let Some(head) = buf.get(..4) else {
            return Err(CdrError::NoHeader { len: buf.len() });
        };
        let order = match u16::from_be_bytes([head[0], head[1]]) {
            0x0000 => Order::Big,
            0x0001 => Order::Little,
            id => return Err(CdrError::Encapsulation { id }),
        };
        Ok(Self { buf, pos: 4, order })
    }

    /// Byte offset of the cursor in the whole message.
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// Moves to the next multiple of `n` from the body's start (XCDR1 aligns a primitive
    /// of size `n` so); the padding may run past the end only if nothing is read after.
    fn align(&mut self, n: usize) {
        let body = self.pos - 4;
        self.pos += (n - body % n) % n;
    }

    /// The next `n` bytes, after aligning to `align`.
    fn take(&mut self, n: usize, align: usize, field: &'static str) -> Result<&'a [u8], CdrError> {
        self.align(align);
        let left = self.buf.len().saturating_sub(self.pos);
        if left < n {
            return Err(CdrError::Truncated {
                offset: self.pos,
                field,
                need: n,
                left,
            });
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        let s = self.take(N, N, field)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if self.order == Order::Big {
            a.reverse();
        }
        Ok(a)
    }

    /// A `uint8`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn u8(&mut self, field: &'static str) -> Result<u8, CdrError> {
        Ok(self.take(1, 1, field)?[0])
    }

    /// A `uint16`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn u16(&mut self, field: &'static str) -> Result<u16, CdrError> {
        Ok(u16::from_le_bytes(self.array::<2>(field)?))
    }

    /// A `float32`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn f32(&mut self, field: &'static str) -> Result<f32, CdrError> {
        Ok(f32::from_le_bytes(self.array::<4>(field)?))
    }

    /// `N` bytes of a fixed `uint8[N]` array (no count), as a UUID is.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn fixed_bytes<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, 1, field)?);
        Ok(a)
    }

    /// A `uint32`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn u32(&mut self, field: &'static str) -> Result<u32, CdrError> {
        Ok(u32::from_le_bytes(self.array::<4>(field)?))
    }

    /// An `int32`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn i32(&mut self, field: &'static str) -> Result<i32, CdrError> {
        Ok(i32::from_le_bytes(self.array::<4>(field)?))
    }

    /// A `float64`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn f64(&mut self, field: &'static str) -> Result<f64, CdrError> {
        Ok(f64::from_le_bytes(self.array::<8>(field)?))
    }

    /// A `string`.
    ///
    /// # Errors
    /// [`CdrError::Truncated`], [`CdrError::StringTerminator`], [`CdrError::StringUtf8`].
    pub fn string(&mut self, field: &'static str) -> Result<&'a str, CdrError> {
        self.align(4);
        let at = self.pos;
        let len = self.u32(field)?;
        let bytes = self.take(len as usize, 1, field)?;
        let Some((&0, text)) = bytes.split_last() else {
            return Err(CdrError::StringTerminator { offset: at, field, len });
        };
        std::str::from_utf8(text).map_err(|_| CdrError::StringUtf8 { offset: at + 4, field })
    }

    /// A `uint8[]` sequence, borrowed.
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn bytes(&mut self, field: &'static str) -> Result<&'a [u8], CdrError> {
        let n = self.u32(field)? as usize;
        self.take(n, 1, field)
    }

    /// `N` consecutive `float64` (a fixed array, no count).
    ///
    /// # Errors
    /// [`CdrError::Truncated`].
    pub fn f64s<const N: usize>(&mut self, field: &'static str) -> Result<[f64; N], CdrError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64(field)?;
        }
        Ok(out)
    }

    /// A `std_msgs/Header`: `builtin_interfaces/Time stamp` (`int32 sec`, `uint32
    /// nanosec`) then `string frame_id`.
    ///
    /// # Errors
    /// As the fields'.
    pub fn header(&mut self) -> Result<Header<'a>, CdrError> {
        let sec = self.i32("header.stamp.sec")?;
        let nanosec = self.u32("header.stamp.nanosec")?;
        let frame_id = self.string("header.frame_id")?;
        Ok(Header {
            stamp: Time { sec, nanosec },
            frame_id,
        })
    }
}

/// Writes little-endian plain CDR: [`CdrWriter::new`] puts the encapsulation header
/// (`00 01 00 00`), and each primitive is aligned to its size counted from the first byte
/// after that header, as [`CdrReader`] reads it.
#[derive(Debug)]
pub struct CdrWriter<'a>(&'a mut Vec<u8>);

impl<'a> CdrWriter<'a> {
    /// Clears `buf` and writes the encapsulation header into it.
    pub fn new(buf: &'a mut Vec<u8>) -> Self {
        buf.clear();
        buf.extend_from_slice(&[0, 1, 0, 0]);
        Self(buf)
    }

    fn align(&mut self, n: usize) {
        while !(self.0.len() - 4).is_multiple_of(n) {
            self.0.push(0);
        }
    }

    /// A `uint8` (or a `bool`, as 0 or 1).
    pub fn u8(&mut self, v: u8) {
        self.0.push(v);
    }

    /// A `uint16`.
    pub fn u16(&mut self, v: u16) {
        self.align(2);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// A `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// A `string`: a length that counts the NUL, the bytes and the NUL.
    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
    }

    /// A `uint8[]` sequence: its count, then the bytes.
    pub fn bytes(&mut self, b: &[u8]) {
        self.u32(b.len() as u32);
        self.0.extend_from_slice(b);
    }

    /// A fixed `uint8[N]` array (no count).
    pub fn fixed_bytes(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
    }

    /// A `std_msgs/Header`.
    pub fn header(&mut self, stamp: Time, frame_id: &str) {
        self.i32(stamp.sec);
        self.u32(stamp.nanosec);
        self.string(frame_id);
    }
}

/// Decodes a `sensor_msgs/msg/Image`: header, `uint32 height`, `uint32 width`, `string
/// encoding`, `uint8 is_bigendian`, `uint32 step`, `uint8[] data`. The pixels are
/// borrowed from `buf`; their encoding is not checked here (see [`Image::to_rgb`]).
///
/// # Errors
/// [`CdrError`] naming the field and byte offset.
pub fn decode_image(buf: &[u8]) -> Result<Image<'_>, CdrError> {
    let mut r = CdrReader::new(buf)?;
    Ok(Image {
        header: r.header()?,
        height: r.u32("height")?,
        width: r.u32("width")?,
        encoding: r.string("encoding")?,
        is_bigendian: r.u8("is_bigendian")?,
        step: r.u32("step")?,
        data: r.bytes("data")?,
    })
}

/// Decodes a `sensor_msgs/msg/CompressedImage`: header, `string format`, `uint8[] data`.
///
/// # Errors
/// [`CdrError`] naming the field and byte offset.
pub fn decode_compressed_image(buf: &[u8]) -> Result<CompressedImage<'_>, CdrError> {
    let mut r = CdrReader::new(buf)?;
    Ok(CompressedImage {
        header: r.header()?,
        format: r.string("format")?,
        data: r.bytes("data")?,
    })
}

/// Decodes a `nav_msgs/msg/Odometry`: header, `string child_frame_id`, then
/// `PoseWithCovariance` (position x y z, orientation x y z w, `float64[36]` covariance)
/// and `TwistWithCovariance` (linear x y z, angular x y z, `float64[36]` covariance).
///
/// # Errors
/// [`CdrError`] naming the field and byte offset.
pub fn decode_odometry(buf: &[u8]) -> Result<Odometry<'_>, CdrError> {
    let mut r = CdrReader::new(buf)?;
    let header = r.header()?;
    let child_frame_id = r.string("child_frame_id")?;
    let position = r.f64s::<3>("pose.pose.position")?;
    let orientation = r.f64s::<4>("pose.pose.orientation")?;
    let pose_covariance = r.f64s::<36>("pose.covariance")?;
    let linear = r.f64s::<3>("twist.twist.linear")?;
    let angular = r.f64s::<3>("twist.twist.angular")?;
    let twist_covariance = r.f64s::<36>("twist.covariance")?;
    Ok(Odometry {
        header,
        child_frame_id,
        position,
        orientation,
        pose_covariance,
        linear,
        angular,
        twist_covariance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_writer_writes_what_the_reader_reads() {
        let mut buf = Vec::new();
        let mut w = CdrWriter::new(&mut buf);
        w.u8(7);
        w.u16(0x0102);
        w.string("ab");
        w.f64(1.5);
        w.f32(-2.0);
        w.fixed_bytes(&[9; 3]);
        w.bytes(&[4, 5]);
        w.header(Time { sec: -3, nanosec: 4 }, "cam");
        let mut r = CdrReader::new(&buf).unwrap();
        assert_eq!(r.u8("a").unwrap(), 7);
        assert_eq!(r.u16("b").unwrap(), 0x0102);
        assert_eq!(r.string("c").unwrap(), "ab");
        assert_eq!(r.f64("d").unwrap(), 1.5);
        assert_eq!(r.f32("e").unwrap(), -2.0);
        assert_eq!(r.fixed_bytes::<3>("f").unwrap(), [9; 3]);
        assert_eq!(r.bytes("g").unwrap(), &[4, 5]);
        let h = r.header().unwrap();
        assert_eq!((h.stamp, h.frame_id), (Time { sec: -3, nanosec: 4 }, "cam"));
        assert_eq!(r.offset(), buf.len());
        // The float64 sits on a multiple of 8 from the body's start: 1 + pad 1 + 2 + 4 + 3
        // ("ab" and its NUL) = 11, padded to 16.
        assert_eq!(&buf[4 + 16..4 + 24], &1.5f64.to_le_bytes());
    }

    #[test]
    fn big_endian_and_alignment() {
        // BE header; uint8 7; pad 3; uint32 0x01020304; float64 1.0 at body offset 8 (no pad); end at 20.
        let mut m = vec![0, 0, 0, 0, 7, 0, 0, 0, 1, 2, 3, 4];
        m.extend_from_slice(&1.0f64.to_be_bytes());
        let mut r = CdrReader::new(&m).unwrap();
        assert_eq!(r.u8("a").unwrap(), 7);
        assert_eq!(r.u32("b").unwrap(), 0x0102_0304);
        assert_eq!(r.f64("c").unwrap(), 1.0);
        assert!(matches!(r.u8("d"), Err(CdrError::Truncated { offset: 20, .. })));
    }

    #[test]
    fn refuses_xcdr2_and_short_input() {
        assert_eq!(
            CdrReader::new(&[0, 7, 0, 0]).unwrap_err(),
            CdrError::Encapsulation { id: 7 }
        );
        assert_eq!(CdrReader::new(&[0, 1]).unwrap_err(), CdrError::NoHeader { len: 2 });
    }

    #[test]
    fn strings_need_their_nul() {
        let m = [0, 1, 0, 0, 2, 0, 0, 0, b'a', b'b'];
        let e = CdrReader::new(&m).unwrap().string("s").unwrap_err();
        assert_eq!(
            e,
            CdrError::StringTerminator {
                offset: 4,
                field: "s",
                len: 2
            }
        );
        let m = [0, 1, 0, 0, 0, 0, 0, 0];
        assert!(CdrReader::new(&m).unwrap().string("s").is_err(), "length 0 has no NUL");
        let m = [0, 1, 0, 0, 2, 0, 0, 0, b'a', 0];
        assert_eq!(CdrReader::new(&m).unwrap().string("s").unwrap(), "a");
    }

    #[test]
    fn huge_counts_are_truncation_not_allocation() {
        let m = [0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff, 1];
        let e = CdrReader::new(&m).unwrap().bytes("data").unwrap_err();
        assert!(
            matches!(
                e,
                CdrError::Truncated {
                    offset: 8,
                    need: 0xffff_ffff,
                    left: 1,
                    ..
                }
            ),
            "{e:?}"
        );
    }
}
