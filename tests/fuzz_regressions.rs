//! Regression inputs of the fuzzing work (`fuzz/`, issue 21 item 3), each pinned to the
//! typed error (never a panic) the library gives for it. Crashing inputs the fuzz targets
//! find go here. So far none has crashed (README, "Fuzzing"); what is here is the
//! decompression-bomb guard that the image target's size bound is: before it, `load_rgb`
//! had no bound of its own (only the `image` crate's 512 MiB allocation limit, reported as
//! a decode error), so a 68-byte PNG declaring 8193 × 8192 pixels (200 MB as RGB8) went
//! to the decoder.

mod common;

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
    use marsupial::replay::pixels::{PixelError, rgb_from_compressed};
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

#[test]
fn a_malformed_log_that_panics_the_mcap_reader_is_a_typed_error() {
    use marsupial::replay::ReplayError;
    use marsupial::replay::log::{Log, LogFault};
    // Found by fuzzing the replay's decoding: the `mcap` reader (0.26) overflows a
    // subtraction on this 1 KB file; `replay::log` contains it as a corrupt-log error.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fuzz/replay-mcap-sub-overflow.mcap");
    let bytes = std::fs::read(&path).unwrap();
    let log = match Log::from_bytes(&path, bytes) {
        Ok(log) => log,
        Err(e) => {
            assert!(matches!(e, ReplayError::Log { .. }), "{e}");
            return;
        }
    };
    let topics: Vec<String> = log.topics().keys().cloned().collect();
    let names: Vec<&str> = topics.iter().map(String::as_str).collect();
    let faults: Vec<ReplayError> = log.messages(&names).filter_map(Result::err).collect();
    assert!(
        faults.iter().any(|e| matches!(
            e,
            ReplayError::Log {
                fault: LogFault::Corrupt { .. },
                ..
            }
        )),
        "{faults:?}"
    );
}
