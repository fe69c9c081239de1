//! RGBA8 images: PNG reading and writing (through the `png` crate) and bilinear sampling
//! in texture coordinates.

use std::io::{BufRead, Seek, Write};
use std::path::Path;

use crate::AppError;

/// An RGBA image with 8 bits per channel, rows from the top, non-premultiplied alpha.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, row by row from the top.
    pub pixels: Vec<[u8; 4]>,
}

/// Largest accepted side of an image (decoded or created), to bound memory.
pub const MAX_SIDE: u32 = 16384;

/// Largest PNG accepted for decoding, in bytes of pixels decoded to 8 bits per channel
/// (1 GiB: a [`MAX_SIDE`] x [`MAX_SIDE`] RGBA image). Larger declared sizes are refused
/// from the header, before any pixel memory is allocated; the decoder's own buffers
/// (rows, metadata chunks) are held to the same bound.
pub const MAX_DECODED_BYTES: usize = 1 << 30;

impl Image {
    /// A `width` x `height` image filled with `fill`; both sides must be 1 to [`MAX_SIDE`].
    pub fn new(width: u32, height: u32, fill: [u8; 4]) -> Result<Self, AppError> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(AppError::Input(format!(
                "image size {width}x{height}: each side must be 1 to {MAX_SIDE}"
            )));
        }
        Ok(Self {
            width,
            height,
            pixels: vec![fill; width as usize * height as usize],
        })
    }

    /// The pixel at column `x`, row `y` (from the top).
    pub fn get(&self, x: u32, y: u32) -> [u8; 4] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Sets the pixel at column `x`, row `y` (from the top).
    pub fn set(&mut self, x: u32, y: u32, c: [u8; 4]) {
        let w = self.width as usize;
        self.pixels[y as usize * w + x as usize] = c;
    }

    /// Bilinear sample at texture coordinates (u, v) in [0, 1]^2 (v = 0 is the bottom row,
    /// as OBJ `vt` has it); coordinates outside are clamped to the border. Channels in
    /// [0, 255] as floats.
    pub fn sample_bilinear(&self, u: f64, v: f64) -> [f64; 4] {
        let (w, h) = (self.width as f64, self.height as f64);
        let x = (u.clamp(0.0, 1.0) * w - 0.5).clamp(0.0, w - 1.0);
        let y = ((1.0 - v.clamp(0.0, 1.0)) * h - 0.5).clamp(0.0, h - 1.0);
        let (x0, y0) = (x.floor() as u32, y.floor() as u32);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let mut out = [0.0; 4];
        let corners = [
            (x0, y0, (1.0 - fx) * (1.0 - fy)),
            (x1, y0, fx * (1.0 - fy)),
            (x0, y1, (1.0 - fx) * fy),
            (x1, y1, fx * fy),
        ];
        for (cx, cy, wgt) in corners {
            let p = self.get(cx, cy);
            for (o, c) in out.iter_mut().zip(p) {
                *o += wgt * c as f64;
            }
        }
        out
    }

    /// Decodes a PNG of any colour type and bit depth into RGBA8. Sides over
    /// [`MAX_SIDE`] and decoded sizes over [`MAX_DECODED_BYTES`] are refused before the
    /// pixels are allocated.
    pub fn decode_png(reader: impl BufRead + Seek) -> Result<Self, AppError> {
        let err = |e: &dyn std::fmt::Display| AppError::Image(format!("PNG: {e}"));
        let limits = png::Limits {
            bytes: MAX_DECODED_BYTES,
        };
        let mut dec = png::Decoder::new_with_limits(reader, limits);
        dec.set_transformations(png::Transformations::normalize_to_color8());
        let mut r = dec.read_info().map_err(|e| err(&e))?;
        let (w, h) = (r.info().width, r.info().height);
        if w > MAX_SIDE || h > MAX_SIDE {
            return Err(AppError::Image(format!(
                "PNG of {w}x{h} pixels: each side must be at most {MAX_SIDE}"
            )));
        }
        let size = r
            .output_buffer_size()
            .filter(|&s| s <= MAX_DECODED_BYTES)
            .ok_or_else(|| {
                AppError::Image(format!(
                    "PNG of {w}x{h} pixels ({:?}, {} bits): more than {} MiB decoded",
                    r.info().color_type,
                    r.info().bit_depth as u8,
                    MAX_DECODED_BYTES >> 20
                ))
            })?;
        let mut buf = vec![0; size];
        let info = r.next_frame(&mut buf).map_err(|e| err(&e))?;
        let data = &buf[..info.buffer_size()];
        let n = w as usize * h as usize;
        let pixels: Vec<[u8; 4]> = match info.color_type {
            png::ColorType::Rgba => data
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            png::ColorType::Rgb => data
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2], 255])
                .collect(),
            png::ColorType::GrayscaleAlpha => data
                .chunks_exact(2)
                .map(|c| [c[0], c[0], c[0], c[1]])
                .collect(),
            png::ColorType::Grayscale => data.iter().map(|&g| [g, g, g, 255]).collect(),
            png::ColorType::Indexed => return Err(err(&"palette not expanded")),
        };
        if pixels.len() != n || info.bit_depth != png::BitDepth::Eight {
            return Err(err(&"unexpected decoded layout"));
        }
        Ok(Self {
            width: w,
            height: h,
            pixels,
        })
    }

    /// Reads a PNG file; the error names the file.
    pub fn read_png(path: &Path) -> Result<Self, AppError> {
        let f = std::fs::File::open(path)
            .map_err(|e| AppError::Image(format!("{}: {e}", path.display())))?;
        Self::decode_png(std::io::BufReader::new(f)).map_err(|e| match e {
            AppError::Image(m) => AppError::Image(format!("{}: {m}", path.display())),
            other => other,
        })
    }

    /// Encodes the image as an RGBA8 PNG.
    pub fn encode_png(&self, w: impl Write) -> Result<(), AppError> {
        let err = |e: png::EncodingError| AppError::Image(format!("PNG: {e}"));
        let mut enc = png::Encoder::new(w, self.width, self.height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().map_err(err)?;
        wr.write_image_data(self.pixels.as_flattened())
            .map_err(err)?;
        wr.finish().map_err(err)
    }

    /// Halves-or-more downsampling by an integer `factor` (box filter), used for
    /// supersampled anti-aliasing.
    pub fn downsample(&self, factor: u32) -> Self {
        if factor <= 1 {
            return self.clone();
        }
        let (w, h) = (self.width / factor, self.height / factor);
        let mut pixels = Vec::with_capacity(w as usize * h as usize);
        let n = factor * factor;
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0u32; 4];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let p = self.get(x * factor + dx, y * factor + dy);
                        for (a, c) in acc.iter_mut().zip(p) {
                            *a += c as u32;
                        }
                    }
                }
                pixels.push(acc.map(|a| ((a + n / 2) / n) as u8));
            }
        }
        Self {
            width: w,
            height: h,
            pixels,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_is_exact() {
        let mut img = Image::new(7, 5, [0, 0, 0, 0]).unwrap();
        for y in 0..5 {
            for x in 0..7 {
                img.set(x, y, [x as u8 * 30, y as u8 * 50, 200, (x * y) as u8 * 9]);
            }
        }
        let mut bytes = Vec::new();
        img.encode_png(&mut bytes).unwrap();
        let back = Image::decode_png(std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(back, img);
    }

    /// A PNG that declares `w` x `h` pixels of `color` at 8 or 16 bits but holds one byte
    /// of pixel data.
    fn declared_png(w: u32, h: u32, color: png::ColorType, depth: png::BitDepth) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(color);
        enc.set_depth(depth);
        let mut wr = enc.write_header().unwrap();
        // A complete zlib stream of one stored zero byte: far fewer pixels than declared.
        let zlib = [
            0x78, 0x01, 0x01, 0x01, 0x00, 0xfe, 0xff, 0x00, 0x00, 0x01, 0x00, 0x01,
        ];
        wr.write_chunk(png::chunk::IDAT, &zlib).unwrap();
        drop(wr);
        bytes
    }

    #[test]
    fn decoded_size_is_bounded_from_the_header() {
        use png::{BitDepth, ColorType};
        // Sides over the limit are refused from the header, before any pixel memory.
        for (w, h) in [
            (MAX_SIDE + 1, 1),
            (1, MAX_SIDE + 1),
            (u32::MAX >> 1, MAX_SIDE),
        ] {
            let wide = declared_png(w, h, ColorType::Rgba, BitDepth::Sixteen);
            let e = Image::decode_png(std::io::Cursor::new(wide)).unwrap_err();
            // The decoder's own bound may refuse a row of 2^31 pixels first.
            let refused = |m: &str| m.contains("at most") || m.contains("limits are exceeded");
            assert!(matches!(&e, AppError::Image(m) if refused(m)), "{e}");
        }
        // 8192 x 8192 RGBA of 8 bits (256 MiB) passes the checks and fails only on its
        // missing pixel data.
        let large = declared_png(8192, 8192, ColorType::Rgba, BitDepth::Eight);
        let e = Image::decode_png(std::io::Cursor::new(large)).unwrap_err();
        let AppError::Image(m) = &e else {
            panic!("{e}")
        };
        assert!(!m.contains("MiB decoded") && !m.contains("limits"), "{m}");
    }

    #[test]
    fn garbage_is_an_image_error() {
        let e = Image::decode_png(std::io::Cursor::new(b"not a png".to_vec())).unwrap_err();
        assert!(matches!(e, AppError::Image(_)));
    }

    #[test]
    fn bilinear_hits_texel_centres_and_averages_between() {
        let mut img = Image::new(2, 1, [0, 0, 0, 255]).unwrap();
        img.set(1, 0, [200, 100, 50, 255]);
        assert_eq!(img.sample_bilinear(0.25, 0.5)[0], 0.0);
        assert_eq!(img.sample_bilinear(0.75, 0.5)[0], 200.0);
        assert!((img.sample_bilinear(0.5, 0.5)[0] - 100.0).abs() < 1e-9);
        // v = 1 is the top row.
        let mut tall = Image::new(1, 2, [0, 0, 0, 255]).unwrap();
        tall.set(0, 0, [255, 0, 0, 255]);
        assert_eq!(tall.sample_bilinear(0.5, 0.9)[0], 255.0);
        assert_eq!(tall.sample_bilinear(0.5, 0.1)[0], 0.0);
    }
}
