//! Grey images in floating point and their pyramids, the input of corner detection and
//! Lucas–Kanade tracking.

use crate::perception::image::RgbView;

/// A grey image, one `f32` per pixel (0–255), row-major.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GreyImage {
    width: usize,
    height: usize,
    data: Vec<f32>,
}

impl GreyImage {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0.0; width * height],
        }
    }

    /// From row-major values; `None` when `data` is not `width × height` long.
    pub fn from_vec(width: usize, height: usize, data: Vec<f32>) -> Option<Self> {
        (data.len() == width * height).then_some(Self { width, height, data })
    }

    /// Width, px.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height, px.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, row-major.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The pixels, row-major, mutable.
    pub fn data_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }

    /// Pixel (x, y); callers keep it in range.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// Resizes (keeping the allocation when it is large enough).
    pub fn resize(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height, 0.0);
    }

    /// Writes the luma (R + 2G + B)/4 of `src` into `self`, resized to match.
    pub fn set_from_rgb(&mut self, src: &RgbView<'_>) {
        self.resize(src.width(), src.height());
        for (o, p) in self.data.iter_mut().zip(src.as_bytes().chunks_exact(3)) {
            *o = (p[0] as f32 + 2.0 * p[1] as f32 + p[2] as f32) * 0.25;
        }
    }

    /// Bilinear sample at (x, y), pixel centres at integers; `None` outside
    /// [0, w − 1] × [0, h − 1].
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x <= (self.width - 1) as f64 && y <= (self.height - 1) as f64) {
            return None;
        }
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let top = self.at(x0, y0) * (1.0 - fx) + self.at(x1, y0) * fx;
        let bottom = self.at(x0, y1) * (1.0 - fx) + self.at(x1, y1) * fx;
        Some(top * (1.0 - fy) + bottom * fy)
    }
}

/// A Gaussian pyramid: level 0 the image, each next level blurred with the 5-tap
/// binomial [1 4 6 4 1]/16 in each direction and halved ((w + 1)/2 × (h + 1)/2).
/// Buffers are kept between frames.
#[derive(Debug, Clone, Default)]
pub struct GreyPyramid {
    levels: Vec<GreyImage>,
    scratch: Vec<f32>,
}

impl GreyPyramid {
    /// A pyramid of `levels` levels (at least 1).
    pub fn new(levels: usize) -> Self {
        Self {
            levels: vec![GreyImage::default(); levels.max(1)],
            scratch: Vec::new(),
        }
    }

    /// Level `k` (0 is full resolution).
    pub fn level(&self, k: usize) -> &GreyImage {
        &self.levels[k]
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a pyramid has at least one level.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Builds every level from `src`'s luma.
    pub fn build_from_rgb(&mut self, src: &RgbView<'_>) {
        self.levels[0].set_from_rgb(src);
        self.build_upper();
    }

    /// Builds every level from a grey image.
    pub fn build_from_grey(&mut self, src: &GreyImage) {
        self.levels[0].resize(src.width(), src.height());
        self.levels[0].data_mut().copy_from_slice(src.data());
        self.build_upper();
    }

    fn build_upper(&mut self) {
        for k in 1..self.levels.len() {
            let (lower, upper) = self.levels.split_at_mut(k);
            downsample(&lower[k - 1], &mut upper[0], &mut self.scratch);
        }
    }
}

/// Blurs `src` with [1 4 6 4 1]/16 (edges clamped) and keeps every other pixel.
fn downsample(src: &GreyImage, dst: &mut GreyImage, scratch: &mut Vec<f32>) {
    let (w, h) = (src.width(), src.height());
    let (dw, dh) = (w.div_ceil(2).max(1), h.div_ceil(2).max(1));
    // Horizontal pass at the kept columns, all rows.
    scratch.resize(dw * h, 0.0);
    let k = [1.0f32, 4.0, 6.0, 4.0, 1.0];
    for y in 0..h {
        let row = &src.data()[y * w..(y + 1) * w];
        for dx in 0..dw {
            let x = (2 * dx) as isize;
            let mut s = 0.0;
            for (i, kk) in k.iter().enumerate() {
                let xi = (x + i as isize - 2).clamp(0, w as isize - 1) as usize;
                s += kk * row[xi];
            }
            scratch[y * dw + dx] = s / 16.0;
        }
    }
    dst.resize(dw, dh);
    let out = dst.data_mut();
    for dy in 0..dh {
        let y = (2 * dy) as isize;
        for dx in 0..dw {
            let mut s = 0.0;
            for (i, kk) in k.iter().enumerate() {
                let yi = (y + i as isize - 2).clamp(0, h as isize - 1) as usize;
                s += kk * scratch[yi * dw + dx];
            }
            out[dy * dw + dx] = s / 16.0;
        }
    }
}
