//! Regression inputs of the fuzzing work (`fuzz/`, issue 21 item 3), each pinned to the
//! typed error (never a panic) the library gives for it. Crashing inputs the fuzz targets
//! find go here:
//! * an indexed PNG whose palette is not a whole number of RGB entries, which panicked
//!   inside the `png` decoder (found by the image target in a 30 s CI run);
//! * two MCAP files the replay target found: a record running past its chunk (a
//!   subtraction overflow in the `mcap` reader) and a string declared longer than its
//!   record (a 1.3 GB reservation), both now refused by `replay::preflight`;
//! * the decompression-bomb guard that the image target's size bound is: before it,
//!   `load_rgb` had no bound of its own (only the `image` crate's 512 MiB allocation
//!   limit, reported as a decode error), so a 68-byte PNG declaring 8193 × 8192 pixels
//!   (200 MB as RGB8) went to the decoder.

use crate::common;

use common::TempDir;
use marsupial::image_io::{DEFAULT_MAX_PIXELS, ImageFileError, decode_rgb, load_rgb, save_png};
use marsupial::perception::RgbImage;
use std::path::Path;

/// CRC-32 (ISO-HDLC, as PNG chunks use).
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
        }
    }
    !c
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// A 68-byte PNG whose header declares a `width`×`height` RGB8 image, with an empty
/// pixel stream (a decompression bomb's shape: a real one's stream of equal pixels
/// compresses about 1000:1, so its file is small too).
fn png_declaring(width: u32, height: u32) -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    chunk(&mut png, b"IHDR", &ihdr);
    // zlib: one final stored block of no bytes, then Adler-32 of nothing (1).
    chunk(
        &mut png,
        b"IDAT",
        &[0x78, 0x01, 0x01, 0x00, 0x00, 0xff, 0xff, 0, 0, 0, 1],
    );
    chunk(&mut png, b"IEND", &[]);
    png
}

/// Adler-32, as zlib streams end with.
fn adler32(bytes: &[u8]) -> u32 {
    let (mut a, mut b) = (1u32, 0u32);
    for &x in bytes {
        a = (a + u32::from(x)) % 65_521;
        b = (b + a) % 65_521;
    }
    (b << 16) | a
}

/// A 2 × 1 indexed (8-bit palette) PNG with the given `PLTE` bytes and pixel indices 0, 1;
/// the pixel stream is one stored zlib block.
fn indexed_png(palette: &[u8]) -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&2u32.to_be_bytes());
    ihdr.extend_from_slice(&1u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 3, 0, 0, 0]);
    chunk(&mut png, b"IHDR", &ihdr);
    chunk(&mut png, b"PLTE", palette);
    let raw = [0u8, 0, 1]; // filter "none", then the two indices
    let mut idat = vec![0x78, 0x01, 0x01, 3, 0, !3, 0xff];
    idat.extend_from_slice(&raw);
    idat.extend_from_slice(&adler32(&raw).to_be_bytes());
    chunk(&mut png, b"IDAT", &idat);
    chunk(&mut png, b"IEND", &[]);
    png
}

#[test]
fn a_palette_of_partial_entries_is_a_decode_error_not_a_decoder_panic() {
    use marsupial::msgs::pixels::{PixelError, rgb_from_compressed};
    // Whole entries decode, through both decoders.
    let good = indexed_png(&[10, 20, 30, 200, 150, 100]);
    let im = decode_rgb(&good, Path::new("good.png"), DEFAULT_MAX_PIXELS).unwrap();
    assert_eq!(im.as_bytes(), &[10, 20, 30, 200, 150, 100]);
    assert_eq!(rgb_from_compressed("png", &good).unwrap().as_bytes(), im.as_bytes());
    // 4, 5, 7 and 767 bytes: the decoder checks only 3..=768, then expanded the indices
    // past the partial last entry.
    for len in [4usize, 5, 7, 767] {
        let palette: Vec<u8> = (0..len).map(|i| (i * 7) as u8).collect();
        let png = indexed_png(&palette);
        match decode_rgb(&png, Path::new("partial.png"), DEFAULT_MAX_PIXELS) {
            Err(ImageFileError::Decode { reason, .. }) => {
                assert!(reason.contains(&format!("PLTE chunk is {len} bytes")), "{reason}");
            }
            other => panic!("PLTE of {len} bytes: expected a decode error, got {other:?}"),
        }
        assert!(
            matches!(rgb_from_compressed("png", &png), Err(PixelError::Decode { .. })),
            "PLTE of {len} bytes through replay"
        );
    }
}

#[test]
fn a_decompression_bomb_is_refused_before_decoding() {
    let dir = TempDir::new("fuzz-bomb");
    // 65535 × 65535 RGB8 would be 12 GiB; 8193 × 8192 is one column over the default.
    for (w, h) in [(65_535, 65_535), (8193, 8192)] {
        let file = dir.0.join(format!("bomb-{w}x{h}.png"));
        let png = png_declaring(w, h);
        assert_eq!(png.len(), 68);
        std::fs::write(&file, png).unwrap();
        match load_rgb(&file) {
            Err(ImageFileError::TooLarge {
                width,
                height,
                max_pixels,
                ..
            }) => {
                assert_eq!((width, height, max_pixels), (w, h, DEFAULT_MAX_PIXELS));
            }
            other => panic!("{w}×{h}: expected TooLarge, got {other:?}"),
        }
        let message = load_rgb(&file).unwrap_err().to_string();
        assert!(
            message.contains("too large") && message.contains(&format!("{w}×{h}")),
            "{message}"
        );
    }
}

#[test]
fn the_pixel_bound_is_inclusive_and_caller_chosen() {
    let dir = TempDir::new("fuzz-bound");
    let file = dir.0.join("small.png");
    let im = RgbImage::from_raw(16, 12, (0..16 * 12 * 3).map(|i| (i % 251) as u8).collect()).unwrap();
    save_png(&file, &im).unwrap();
    let bytes = std::fs::read(&file).unwrap();
    let back = decode_rgb(&bytes, &file, 16 * 12).unwrap();
    assert_eq!(back.as_bytes(), im.as_bytes());
    assert!(matches!(
        decode_rgb(&bytes, &file, 16 * 12 - 1),
        Err(ImageFileError::TooLarge {
            width: 16,
            height: 12,
            max_pixels: 191,
            ..
        })
    ));
}

#[test]
fn a_header_too_short_to_declare_a_size_is_a_decode_error() {
    let png = png_declaring(64, 48);
    for cut in [8, 12, 20, 30] {
        assert!(
            matches!(
                decode_rgb(&png[..cut], Path::new("cut.png"), DEFAULT_MAX_PIXELS),
                Err(ImageFileError::Decode { .. })
            ),
            "cut at {cut}"
        );
    }
}

#[test]
fn a_compressed_frame_in_a_replayed_log_is_held_to_the_same_bound() {
    use marsupial::msgs::pixels::{PixelError, rgb_from_compressed};
    // Within the side limit (16384) but over the pixel bound: refused from the header,
    // before the decoder allocates; as are sides over 16384.
    for (w, h) in [(8193, 8192), (16384, 16384), (20000, 1)] {
        match rgb_from_compressed("png", &png_declaring(w, h)) {
            Err(PixelError::Size { width, height }) => assert_eq!((width, height), (w, h)),
            other => panic!("{w}×{h}: {other:?}"),
        }
    }
    // At the bound the header passes and the empty pixel stream fails to decode.
    assert!(matches!(
        rgb_from_compressed("png", &png_declaring(8192, 8192)),
        Err(PixelError::Decode { .. })
    ));
}

/// Reads a replay fixture found by fuzzing and returns why `Log::from_bytes` refused it.
fn refused_log(name: &str) -> marsupial::replay::preflight::Flaw {
    use marsupial::replay::ReplayError;
    use marsupial::replay::log::{Log, LogFault};
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(name);
    let bytes = std::fs::read(&path).unwrap();
    match Log::from_bytes(&path, bytes) {
        Err(ReplayError::Log {
            fault: LogFault::Malformed(flaw),
            ..
        }) => flaw,
        Err(e) => panic!("{name}: {e}"),
        Ok(_) => panic!("{name}: read as a log"),
    }
}

#[test]
fn a_record_running_past_its_chunk_is_refused_before_the_mcap_reader_sees_it() {
    use marsupial::replay::preflight::Flaw;
    // Found by fuzzing the replay: on this 4.5 KB file the `mcap` reader (0.26) subtracts
    // past zero (a panic with overflow checks, a wrapped count without them). It was
    // first contained as a panic; the preflight now refuses the file by name.
    let flaw = refused_log("replay-mcap-sub-overflow.mcap");
    assert_eq!(
        flaw,
        Flaw::ChunkOverrun {
            chunk: 33,
            offset: 2867
        }
    );
    assert!(flaw.to_string().contains("runs past the end of the chunk"), "{flaw}");
}

#[test]
fn a_string_longer_than_its_record_is_refused_before_the_reader_reserves_it() {
    use marsupial::replay::preflight::Flaw;
    // Found by fuzzing the replay, each a schema record declaring a name of over 1 GB,
    // which the reader reserved before finding the record too short: in the data
    // section; inside a chunk the file ends in (the reader streams a chunk's records);
    // in a summary behind a footer whose length field is garbage (the reader ignores it).
    for (name, at, declared) in [
        ("replay-mcap-string-reservation.mcap", 566, 1_347_440_720),
        ("replay-mcap-string-in-cut-chunk.mcap", 78, 1_948_416_768),
        ("replay-mcap-summary-behind-odd-footer.mcap", 986, 1_879_048_216),
    ] {
        match refused_log(name) {
            Flaw::LongString {
                offset,
                opcode,
                declared: d,
                ..
            } => assert_eq!((offset, opcode, d), (at, 0x03, declared), "{name}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn records_the_mcap_reader_would_overflow_or_slice_past_are_refused() {
    use marsupial::replay::preflight::Flaw;
    // Found by fuzzing the replay: a record length of u64::MAX (the reader adds the
    // header's 9 bytes to it) and an attachment with no room for its CRC (the reader
    // slices to 4 bytes before the end).
    assert_eq!(
        refused_log("replay-mcap-huge-record.mcap"),
        Flaw::HugeRecord {
            offset: 921,
            declared: u64::MAX
        }
    );
    let flaw = refused_log("replay-mcap-attachment-without-crc.mcap");
    assert!(matches!(flaw, Flaw::ShortRecord { opcode: 0x09, .. }), "{flaw:?}");
}

#[test]
fn a_record_the_preflight_walk_does_not_reach_is_still_checked_before_the_reader_parses_it() {
    use marsupial::replay::ReplayError;
    use marsupial::replay::log::{Log, LogFault};
    use marsupial::replay::preflight::Flaw;
    // Found by the replay target in CI (30 s run) after the replay's own message stream
    // came in: a schema record declaring a 1.95 GB string that the stream handed to
    // `mcap::parse_record` (which reserves the declared length) though the file's
    // preflight walk had not descended to it. The stream now checks every record it
    // parses (`preflight::record_flaw`).
    let name = "replay-mcap-string-in-stream-record.mcap";
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(name);
    let bytes = std::fs::read(&path).unwrap();
    // Listing the topics stops quietly at the fault; reading the messages reports it.
    let log = Log::from_bytes(&path, bytes).unwrap();
    let fault = log.messages(&[]).find_map(Result::err);
    let flaw = match fault {
        Some(ReplayError::Log {
            fault: LogFault::Malformed(flaw) | LogFault::MalformedChunk { flaw, .. },
            ..
        }) => flaw,
        other => panic!("{name}: {other:?}"),
    };
    assert!(matches!(flaw, Flaw::LongString { opcode: 0x03, .. }), "{flaw:?}");
}
