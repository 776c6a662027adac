//! Every camera encoding `marsupial::msgs::pixels` reads, decoded from a real photo: the
//! photo is encoded to the layout here by a straightforward reference encoder (BT.601
//! limited range, chroma averaged over its block; Bayer: one sample a pixel), decoded by
//! the crate, and compared with the photo. Tolerances are mean absolute errors per
//! channel, the loss the layout itself costs (chroma subsampling, demosaicing), with a
//! margin (measured here: at most 1.4 for 4:2:2, 2.5 for 4:2:0, 3.0 for Bayer, 1.7 for
//! JPEG): 0 for the lossless layouts, 2 for 4:2:2, 3.5 for 4:2:0, 6 for a bilinear
//! demosaic, 3 for JPEG at quality 90, 0.01 for a 2× area down-scale against the 2×2
//! box mean. Skipped, with a note,
//! without `../shared/data/photos`.

use marsupial::image_io::load_rgb;
use marsupial::msgs::camera_frame::{CameraBytes, FrameDecoder};
use marsupial::msgs::pixels::{PixelError, rgb_from_compressed, rgb_from_raw};
use marsupial::msgs::rescale::Rescaler;
use marsupial::perception::RgbImage;
use std::path::Path;

/// The photo's top-left `w × h` (even sides), or `None` without the photos.
fn photo(name: &str, w: usize, h: usize) -> Option<RgbImage> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/photos")
        .join(name);
    if !path.exists() {
        eprintln!("skipped: {} is absent", path.display());
        return None;
    }
    let im = load_rgb(&path).unwrap();
    let mut out = RgbImage::new(w, h);
    for y in 0..h {
        for x in 0..w {
            out.put(x, y, im.view().get(x, y).unwrap());
        }
    }
    Some(out)
}

const PHOTOS: [&str; 2] = ["color/mcc_ccm_test.jpg", "color/fruits.jpg"];
/// A 640×480 photo, for a camera mode twice the profile's size.
const BIG: &str = "backgrounds/aero1.jpg";
const W: usize = 320;
const H: usize = 240;
/// Bytes of padding after every row, so each layout's `step` is exercised.
const PAD: usize = 6;

fn px(im: &RgbImage, x: usize, y: usize) -> [f64; 3] {
    let p = &im.as_bytes()[(y * im.width() + x) * 3..][..3];
    [p[0], p[1], p[2]].map(f64::from)
}

/// BT.601 limited range, real-valued: (Y′, Cb, Cr).
fn ycbcr(rgb: [f64; 3]) -> [f64; 3] {
    let [r, g, b] = rgb.map(|c| c / 255.0);
    let y = 0.299 * r + 0.587 * g + 0.114 * b;
    [
        16.0 + 219.0 * y,
        128.0 + 224.0 * (b - y) / 1.772,
        128.0 + 224.0 * (r - y) / 1.402,
    ]
}

fn q(v: f64) -> u8 {
    v.round().clamp(0.0, 255.0) as u8
}

/// Mean chroma (Cb, Cr) over the `bw × bh` block at (x, y).
fn chroma(im: &RgbImage, x: usize, y: usize, bw: usize, bh: usize) -> [u8; 2] {
    let mut acc = [0.0; 2];
    for yy in y..y + bh {
        for xx in x..x + bw {
            let c = ycbcr(px(im, xx, yy));
            acc[0] += c[1];
            acc[1] += c[2];
        }
    }
    acc.map(|a| q(a / (bw * bh) as f64))
}

fn luma(im: &RgbImage, x: usize, y: usize) -> u8 {
    q(ycbcr(px(im, x, y))[0])
}

/// Packed 4:2:2, `uyvy` or not (`yuyv`).
fn encode_422(im: &RgbImage, uyvy: bool) -> Vec<u8> {
    let mut out = Vec::new();
    for y in 0..im.height() {
        for x in (0..im.width()).step_by(2) {
            let [cb, cr] = chroma(im, x, y, 2, 1);
            let (y0, y1) = (luma(im, x, y), luma(im, x + 1, y));
            out.extend(if uyvy { [cb, y0, cr, y1] } else { [y0, cb, y1, cr] });
        }
        out.extend([0xEE; PAD]);
    }
    out
}

/// 4:2:0 semi-planar, `nv21` or not (`nv12`).
fn encode_nv(im: &RgbImage, nv21: bool) -> Vec<u8> {
    let mut out = Vec::new();
    for y in 0..im.height() {
        out.extend((0..im.width()).map(|x| luma(im, x, y)));
        out.extend([0xEE; PAD]);
    }
    for y in (0..im.height()).step_by(2) {
        for x in (0..im.width()).step_by(2) {
            let [cb, cr] = chroma(im, x, y, 2, 2);
            out.extend(if nv21 { [cr, cb] } else { [cb, cr] });
        }
        out.extend([0xEE; PAD]);
    }
    out
}

/// The sample of `tile` (channels of the 2×2 tile in reading order) at each pixel.
fn encode_bayer(im: &RgbImage, tile: [usize; 4]) -> Vec<u8> {
    let mut out = Vec::new();
    for y in 0..im.height() {
        out.extend((0..im.width()).map(|x| im.as_bytes()[(y * im.width() + x) * 3 + tile[(y % 2) * 2 + x % 2]]));
        out.extend([0xEE; PAD]);
    }
    out
}

/// Interleaved channels in `order` (indices into RGB; 3 is an alpha of 255).
fn encode_interleaved(im: &RgbImage, order: &[usize]) -> Vec<u8> {
    let mut out = Vec::new();
    for row in im.as_bytes().chunks(im.width() * 3) {
        for p in row.chunks(3) {
            out.extend(order.iter().map(|&i| if i == 3 { 255 } else { p[i] }));
        }
        out.extend([0xEE; PAD]);
    }
    out
}

/// Mean absolute error per channel.
fn mae(a: &RgbImage, b: &RgbImage) -> [f64; 3] {
    assert_eq!((a.width(), a.height()), (b.width(), b.height()));
    let mut acc = [0.0; 3];
    for (p, q) in a.as_bytes().chunks(3).zip(b.as_bytes().chunks(3)) {
        for c in 0..3 {
            acc[c] += f64::from(p[c].abs_diff(q[c]));
        }
    }
    acc.map(|s| s / (a.width() * a.height()) as f64)
}

fn check(name: &str, photo_name: &str, got: &RgbImage, want: &RgbImage, tolerance: f64) {
    let e = mae(got, want);
    eprintln!("{photo_name} {name}: mean abs error per channel {e:.2?}");
    assert!(
        e.iter().all(|&c| c <= tolerance),
        "{photo_name} {name}: {e:.2?} over {tolerance}"
    );
}

#[test]
fn every_camera_encoding_decodes_a_real_photo() {
    for name in PHOTOS {
        let Some(im) = photo(name, W, H) else { return };
        let (w, h) = (W as u32, H as u32);
        let step = |bytes_per_px: usize| (W * bytes_per_px + PAD) as u32;
        let decode = |enc: &str, step: u32, data: &[u8]| rgb_from_raw(w, h, enc, step, data).unwrap();
        for (enc, order) in [
            ("rgb8", &[0, 1, 2][..]),
            ("bgr8", &[2, 1, 0]),
            ("rgba8", &[0, 1, 2, 3]),
            ("bgra8", &[2, 1, 0, 3]),
        ] {
            let got = decode(enc, step(order.len()), &encode_interleaved(&im, order));
            assert_eq!(got.as_bytes(), im.as_bytes(), "{name} {enc}");
        }
        let grey = encode_interleaved(&im, &[1]);
        let got = decode("mono8", step(1), &grey);
        assert!(
            got.as_bytes()
                .chunks(3)
                .zip(im.as_bytes().chunks(3))
                .all(|(g, p)| g == [p[1]; 3]),
            "{name} mono8"
        );
        for (enc, uyvy) in [
            ("yuyv", false),
            ("yuv422_yuy2", false),
            ("uyvy", true),
            ("yuv422", true),
        ] {
            check(enc, name, &decode(enc, step(2), &encode_422(&im, uyvy)), &im, 2.0);
        }
        for (enc, nv21) in [("nv12", false), ("nv21", true)] {
            check(enc, name, &decode(enc, step(1), &encode_nv(&im, nv21)), &im, 3.5);
        }
        for (enc, tile) in [
            ("bayer_rggb8", [0, 1, 1, 2]),
            ("bayer_bggr8", [2, 1, 1, 0]),
            ("bayer_grbg8", [1, 0, 2, 1]),
            ("bayer_gbrg8", [1, 2, 0, 1]),
        ] {
            check(enc, name, &decode(enc, step(1), &encode_bayer(&im, tile)), &im, 6.0);
        }
        // MJPEG: one JPEG per frame, as `sensor_msgs/CompressedImage`.
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
            .encode(im.as_bytes(), w, h, image::ExtendedColorType::Rgb8)
            .unwrap();
        check("jpeg", name, &rgb_from_compressed("jpeg", &jpeg).unwrap(), &im, 3.0);
    }
}

/// The 2×2 box mean of `im`, the reference of a 2× area down-scale.
fn half(im: &RgbImage) -> RgbImage {
    let mut out = RgbImage::new(im.width() / 2, im.height() / 2);
    for y in 0..out.height() {
        for x in 0..out.width() {
            let mut acc = [0.0; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let p = px(im, 2 * x + dx, 2 * y + dy);
                (0..3).for_each(|c| acc[c] += p[c]);
            }
            out.put(x, y, acc.map(|a| q(a / 4.0)));
        }
    }
    out
}

#[test]
fn a_camera_mode_of_another_size_is_rescaled_to_the_profile_camera() {
    let Some(im) = photo(BIG, 2 * W, 2 * H) else {
        return;
    };
    let want = half(&im);
    // Through the rescaler alone: the area mean is the box mean within rounding.
    let mut out = RgbImage::new(W, H);
    Rescaler::new().fill(&im.view(), &mut out).unwrap();
    check("rescaled rgb", BIG, &out, &want, 0.01);
    // A 640×480 YUYV camera for a 320×240 profile: decoded, then rescaled.
    let yuyv = encode_422(&im, false);
    let mut frame = RgbImage::new(W, H);
    let mut dec = FrameDecoder::new();
    let bytes = CameraBytes::Raw {
        width: 2 * W as u32,
        height: 2 * H as u32,
        encoding: "yuyv",
        step: (4 * W + PAD) as u32,
        data: &yuyv,
    };
    assert_eq!(dec.decode_into(bytes, &mut frame).unwrap(), (2 * W, 2 * H));
    check("yuyv rescaled", BIG, &frame, &want, 2.0);
    // Another aspect ratio: refused by name and sizes, the frame untouched.
    let before = frame.as_bytes().to_vec();
    let mut wide = RgbImage::new(W, H - 40);
    wide.fill([1, 2, 3]);
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
        .encode(
            wide.as_bytes(),
            W as u32,
            (H - 40) as u32,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    let e = dec
        .decode_into(
            CameraBytes::Compressed {
                format: "jpeg",
                data: &jpeg,
            },
            &mut frame,
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            PixelError::Aspect {
                width: 320,
                height: 200,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("320×200") && e.to_string().contains("320×240"),
        "{e}"
    );
    assert_eq!(frame.as_bytes(), &before[..]);
    // A truncated JPEG is a typed error, the frame untouched.
    let cut = CameraBytes::Compressed {
        format: "jpeg",
        data: &jpeg[..30],
    };
    assert!(matches!(
        dec.decode_into(cut, &mut frame),
        Err(PixelError::Decode { .. })
    ));
    assert_eq!(frame.as_bytes(), &before[..]);
}
