//! A PNG silhouette's pixels as the tracer reads them: decoded into the
//! bytes its colour type needs (one a pixel for a grey image, two with
//! alpha, three for colour, four with alpha), never widened to RGBA, and
//! read as a grey level over white.
//!
//! The grey level is the one tiny-skia's decoding gave, to the bit: a
//! pixel with alpha goes through its premultiplication and back (which
//! rounds), then `a · luminance + (1 − a)`. A unit test holds the two
//! against each other on every colour type.

use tiny_skia::ColorU8;

/// The pixels of one PNG image, 8 bits a channel.
pub(super) struct Image {
    pub w: usize,
    pub h: usize,
    channels: usize,
    data: Vec<u8>,
    /// The grey level of each byte value, for the grey images (the same
    /// arithmetic as `grey_of`, so the same bits).
    table: Vec<f64>,
}

/// The grey level over white of an RGBA pixel (straight alpha).
fn grey_of(p: [u8; 4]) -> f64 {
    let a = p[3] as f64 / 255.0;
    let lum = (0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64) / 255.0;
    a * lum + (1.0 - a)
}

impl Image {
    /// Decodes the first frame of a PNG (palettes and low bit depths
    /// expanded to 8 bits, 16 bits stripped to 8, a `tRNS` chunk to alpha:
    /// what tiny-skia asks of the decoder). `Err` holds the decoder's
    /// message.
    pub fn decode(bytes: &[u8]) -> Result<Image, String> {
        let mut decoder = png::Decoder::new(bytes);
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
        let mut data = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut data).map_err(|e| e.to_string())?;
        let (w, h) = (info.width as usize, info.height as usize);
        if info.bit_depth != png::BitDepth::Eight || w == 0 || h == 0 {
            return Err("unsupported bit depth or size".into());
        }
        let channels = match info.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => return Err("indexed PNG is not supported".into()),
        };
        // Rows may be padded past `w * channels` bytes: keep `line_size`.
        let line = info.line_size;
        if line != w * channels {
            let mut packed = Vec::with_capacity(w * h * channels);
            for row in data.chunks(line).take(h) {
                packed.extend_from_slice(&row[..w * channels]);
            }
            data = packed;
        } else {
            data.truncate(w * h * channels);
        }
        // Alpha: premultiplied and back, as tiny-skia's pixmap held it.
        let round_trip = |c: [u8; 4]| {
            let p = ColorU8::from_rgba(c[0], c[1], c[2], c[3])
                .premultiply()
                .demultiply();
            [p.red(), p.green(), p.blue(), p.alpha()]
        };
        match channels {
            2 => {
                for px in data.chunks_exact_mut(2) {
                    let c = round_trip([px[0], px[0], px[0], px[1]]);
                    px.copy_from_slice(&[c[0], c[3]]);
                }
            }
            4 => {
                for px in data.chunks_exact_mut(4) {
                    let c = round_trip([px[0], px[1], px[2], px[3]]);
                    px.copy_from_slice(&c);
                }
            }
            _ => {}
        }
        let table = (0..=255u8).map(|g| grey_of([g, g, g, 255])).collect();
        Ok(Image {
            w,
            h,
            channels,
            data,
            table,
        })
    }

    /// The grey level (0 black … 1 white) of pixel (x, y) over white.
    #[inline]
    pub fn grey(&self, x: usize, y: usize) -> f64 {
        let i = (y * self.w + x) * self.channels;
        match self.channels {
            1 => self.table[self.data[i] as usize],
            2 => {
                let (g, a) = (self.data[i], self.data[i + 1]);
                grey_of([g, g, g, a])
            }
            3 => grey_of([self.data[i], self.data[i + 1], self.data[i + 2], 255]),
            _ => grey_of([
                self.data[i],
                self.data[i + 1],
                self.data[i + 2],
                self.data[i + 3],
            ]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grey levels as the reader had them before: tiny-skia's pixmap
    /// (premultiplied RGBA), demultiplied, then over white.
    fn by_pixmap(bytes: &[u8]) -> Vec<f64> {
        let pm = tiny_skia::Pixmap::decode_png(bytes).unwrap();
        pm.pixels()
            .iter()
            .map(|p| {
                let c = p.demultiply();
                grey_of([c.red(), c.green(), c.blue(), c.alpha()])
            })
            .collect()
    }

    fn encode(
        w: u32,
        h: u32,
        colour: png::ColorType,
        depth: png::BitDepth,
        data: &[u8],
    ) -> Vec<u8> {
        let mut out = Vec::new();
        let mut e = png::Encoder::new(&mut out, w, h);
        e.set_color(colour);
        e.set_depth(depth);
        if colour == png::ColorType::Indexed {
            let palette: Vec<u8> = (0..=255u8).flat_map(|i| [i, 255 - i, i / 2]).collect();
            e.set_palette(palette);
            e.set_trns((0..=255u8).map(|i| i.wrapping_mul(37)).collect::<Vec<u8>>());
        }
        e.write_header().unwrap().write_image_data(data).unwrap();
        out
    }

    #[test]
    fn grey_levels_are_tiny_skias_to_the_bit() {
        let mut next = crate::testing::xorshift(0x5eed);
        let (w, h) = (13u32, 7u32);
        use png::{BitDepth::*, ColorType::*};
        for (colour, depth, bytes_px) in [
            (Grayscale, Eight, 1.0),
            (GrayscaleAlpha, Eight, 2.0),
            (Rgb, Eight, 3.0),
            (Rgba, Eight, 4.0),
            (Rgba, Sixteen, 8.0),
            (Grayscale, Sixteen, 2.0),
            (Grayscale, Two, 0.25),
            (Indexed, Eight, 1.0),
        ] {
            // Rows of whole bytes: 13 two-bit pixels take 4 bytes.
            let row = (w as f64 * bytes_px).ceil() as usize;
            let data: Vec<u8> = (0..row * h as usize).map(|_| next() as u8).collect();
            let png = encode(w, h, colour, depth, &data);
            let img = Image::decode(&png).unwrap();
            let got: Vec<f64> = (0..h as usize)
                .flat_map(|y| (0..w as usize).map(move |x| (x, y)))
                .map(|(x, y)| img.grey(x, y))
                .collect();
            let want = by_pixmap(&png);
            assert_eq!(got.len(), want.len());
            for (g, e) in got.iter().zip(&want) {
                assert_eq!(g.to_bits(), e.to_bits(), "{colour:?} {depth:?}");
            }
        }
    }

    #[test]
    fn a_grey_image_takes_one_byte_a_pixel() {
        let png = encode(
            64,
            32,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[9; 64 * 32],
        );
        let img = Image::decode(&png).unwrap();
        assert_eq!(img.data.len(), 64 * 32);
        assert_eq!(img.data.capacity(), 64 * 32);
    }
}
