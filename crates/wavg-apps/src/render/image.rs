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

    /// Decodes a baseline or progressive JPEG into RGBA8 (the base colour textures of glTF
    /// files are PNG or JPEG). Sides over [`MAX_SIDE`] are refused from the header.
    pub fn decode_jpeg(bytes: &[u8]) -> Result<Self, AppError> {
        use zune_jpeg::zune_core::bytestream::ZCursor;
        use zune_jpeg::zune_core::colorspace::ColorSpace;
        use zune_jpeg::zune_core::options::DecoderOptions;
        let err = |e: &dyn std::fmt::Display| AppError::Image(format!("JPEG: {e}"));
        let options = DecoderOptions::default()
            .jpeg_set_out_colorspace(ColorSpace::RGBA)
            .set_max_width(MAX_SIDE as usize)
            .set_max_height(MAX_SIDE as usize);
        let mut dec = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
        let data = dec.decode().map_err(|e| err(&format!("{e:?}")))?;
        let info = dec.info().ok_or_else(|| err(&"no image header"))?;
        let (w, h) = (info.width as u32, info.height as u32);
        if w == 0 || h == 0 || data.len() != w as usize * h as usize * 4 {
            return Err(err(&"unexpected decoded layout"));
        }
        Ok(Self {
            width: w,
            height: h,
            pixels: data
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
        })
    }

    /// Decodes a PNG or a JPEG, told apart by their first bytes.
    pub fn decode(bytes: &[u8]) -> Result<Self, AppError> {
        if bytes.starts_with(&[0xFF, 0xD8]) {
            Self::decode_jpeg(bytes)
        } else {
            Self::decode_png(std::io::Cursor::new(bytes))
        }
    }

    /// Reads a PNG or JPEG file; the error names the file.
    pub fn read(path: &Path) -> Result<Self, AppError> {
        let bytes =
            std::fs::read(path).map_err(|e| AppError::Image(format!("{}: {e}", path.display())))?;
        Self::decode(&bytes).map_err(|e| match e {
            AppError::Image(m) => AppError::Image(format!("{}: {m}", path.display())),
            other => other,
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

    /// An 8x4 JPEG of one red (204, 26, 38), as Blender saves it.
    const RED_JPEG: &[u8] = &[
        0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 0x4a, 0x46, 0x49, 0x46, 0x00, 0x01, 0x01, 0x00, 0x00,
        0x01, 0x00, 0x01, 0x00, 0x00, 0xff, 0xe1, 0x00, 0x0c, 0x4e, 0x65, 0x6f, 0x47, 0x65, 0x6f,
        0x00, 0x00, 0x00, 0x5a, 0xff, 0xdb, 0x00, 0x43, 0x00, 0x03, 0x02, 0x02, 0x03, 0x02, 0x02,
        0x03, 0x03, 0x03, 0x03, 0x04, 0x03, 0x03, 0x04, 0x05, 0x08, 0x05, 0x05, 0x04, 0x04, 0x05,
        0x0a, 0x07, 0x07, 0x06, 0x08, 0x0c, 0x0a, 0x0c, 0x0c, 0x0b, 0x0a, 0x0b, 0x0b, 0x0d, 0x0e,
        0x12, 0x10, 0x0d, 0x0e, 0x11, 0x0e, 0x0b, 0x0b, 0x10, 0x16, 0x10, 0x11, 0x13, 0x14, 0x15,
        0x15, 0x15, 0x0c, 0x0f, 0x17, 0x18, 0x16, 0x14, 0x18, 0x12, 0x14, 0x15, 0x14, 0xff, 0xdb,
        0x00, 0x43, 0x01, 0x03, 0x04, 0x04, 0x05, 0x04, 0x05, 0x09, 0x05, 0x05, 0x09, 0x14, 0x0d,
        0x0b, 0x0d, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14,
        0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14,
        0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14,
        0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0x14, 0xff, 0xc0, 0x00, 0x11, 0x08, 0x00, 0x04, 0x00,
        0x08, 0x03, 0x01, 0x22, 0x00, 0x02, 0x11, 0x01, 0x03, 0x11, 0x01, 0xff, 0xc4, 0x00, 0x1f,
        0x00, 0x00, 0x01, 0x05, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00,
        0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0x0b, 0xff,
        0xc4, 0x00, 0xb5, 0x10, 0x00, 0x02, 0x01, 0x03, 0x03, 0x02, 0x04, 0x03, 0x05, 0x05, 0x04,
        0x04, 0x00, 0x00, 0x01, 0x7d, 0x01, 0x02, 0x03, 0x00, 0x04, 0x11, 0x05, 0x12, 0x21, 0x31,
        0x41, 0x06, 0x13, 0x51, 0x61, 0x07, 0x22, 0x71, 0x14, 0x32, 0x81, 0x91, 0xa1, 0x08, 0x23,
        0x42, 0xb1, 0xc1, 0x15, 0x52, 0xd1, 0xf0, 0x24, 0x33, 0x62, 0x72, 0x82, 0x09, 0x0a, 0x16,
        0x17, 0x18, 0x19, 0x1a, 0x25, 0x26, 0x27, 0x28, 0x29, 0x2a, 0x34, 0x35, 0x36, 0x37, 0x38,
        0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48, 0x49, 0x4a, 0x53, 0x54, 0x55, 0x56, 0x57,
        0x58, 0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68, 0x69, 0x6a, 0x73, 0x74, 0x75, 0x76,
        0x77, 0x78, 0x79, 0x7a, 0x83, 0x84, 0x85, 0x86, 0x87, 0x88, 0x89, 0x8a, 0x92, 0x93, 0x94,
        0x95, 0x96, 0x97, 0x98, 0x99, 0x9a, 0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa,
        0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba, 0xc2, 0xc3, 0xc4, 0xc5, 0xc6, 0xc7,
        0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda, 0xe1, 0xe2, 0xe3,
        0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf1, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8,
        0xf9, 0xfa, 0xff, 0xc4, 0x00, 0x1f, 0x01, 0x00, 0x03, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06,
        0x07, 0x08, 0x09, 0x0a, 0x0b, 0xff, 0xc4, 0x00, 0xb5, 0x11, 0x00, 0x02, 0x01, 0x02, 0x04,
        0x04, 0x03, 0x04, 0x07, 0x05, 0x04, 0x04, 0x00, 0x01, 0x02, 0x77, 0x00, 0x01, 0x02, 0x03,
        0x11, 0x04, 0x05, 0x21, 0x31, 0x06, 0x12, 0x41, 0x51, 0x07, 0x61, 0x71, 0x13, 0x22, 0x32,
        0x81, 0x08, 0x14, 0x42, 0x91, 0xa1, 0xb1, 0xc1, 0x09, 0x23, 0x33, 0x52, 0xf0, 0x15, 0x62,
        0x72, 0xd1, 0x0a, 0x16, 0x24, 0x34, 0xe1, 0x25, 0xf1, 0x17, 0x18, 0x19, 0x1a, 0x26, 0x27,
        0x28, 0x29, 0x2a, 0x35, 0x36, 0x37, 0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48,
        0x49, 0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67,
        0x68, 0x69, 0x6a, 0x73, 0x74, 0x75, 0x76, 0x77, 0x78, 0x79, 0x7a, 0x82, 0x83, 0x84, 0x85,
        0x86, 0x87, 0x88, 0x89, 0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98, 0x99, 0x9a, 0xa2,
        0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8,
        0xb9, 0xba, 0xc2, 0xc3, 0xc4, 0xc5, 0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5,
        0xd6, 0xd7, 0xd8, 0xd9, 0xda, 0xe2, 0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf2,
        0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8, 0xf9, 0xfa, 0xff, 0xda, 0x00, 0x0c, 0x03, 0x01, 0x00,
        0x02, 0x11, 0x03, 0x11, 0x00, 0x3f, 0x00, 0xf0, 0x2a, 0x28, 0xa2, 0xbf, 0x3f, 0x3f, 0xba,
        0xcf, 0xff, 0xd9,
    ];

    #[test]
    fn jpeg_decodes_to_rgba_and_bad_jpeg_is_an_error() {
        let img = Image::decode(RED_JPEG).unwrap();
        assert_eq!((img.width, img.height, img.pixels.len()), (8, 4, 32));
        for p in &img.pixels {
            assert!(p[0].abs_diff(204) < 12 && p[1].abs_diff(26) < 12, "{p:?}");
            assert!(p[2].abs_diff(38) < 12 && p[3] == 255, "{p:?}");
        }
        for cut in [2, 20, 200, RED_JPEG.len() - 2] {
            let _ = Image::decode(&RED_JPEG[..cut]); // an error or an image, never a panic
        }
        assert!(Image::decode(&RED_JPEG[..2]).is_err());
        assert!(Image::decode(b"neither").is_err());
    }
}
