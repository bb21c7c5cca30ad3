//! A photograph as a fit sees it: the 8-bit sRGB image renders are compared
//! with, the same values unrounded (a 16-bit or float file says more than
//! 8 bits), and the pixels the camera clipped, whose true value is unknown.
//!
//! A channel is saturated at the format's maximum: 255 in an 8-bit file,
//! 65535 in a 16-bit one. A 32-bit float file (OpenEXR, float TIFF) has no
//! maximum: none of its pixels counts as saturated, and values above 1 are
//! clipped to 1 (level 255) like any render.

use super::encoding::Encoding;
use super::Image;
use image::DynamicImage;

/// A decoded photograph.
#[derive(Clone, Debug)]
pub struct Photo {
    /// 8-bit sRGB, what renders are compared with.
    pub image: Image,
    /// The same in unrounded 8-bit sRGB level units (0..255), 3 per pixel.
    pub levels: Vec<f32>,
    /// Indices (y * width + x) of the pixels with a channel at the format's
    /// maximum.
    pub saturated: Vec<u32>,
    /// Indices of the pixels with a channel that is not a number or is
    /// infinite (a float file): their levels are 0, and they say nothing.
    pub non_finite: Vec<u32>,
    pub encoding: Encoding,
    /// Bits per channel of the file: 8, 16 or 32 (float).
    pub bits: u8,
}

impl Photo {
    /// Converts a decoded file whose values are in `encoding`. Alpha is
    /// ignored; grey is taken as equal red, green and blue.
    pub fn from_decoded(img: DynamicImage, encoding: Encoding) -> Photo {
        let (w, h) = (img.width(), img.height());
        let mut acc = Accumulator::new(w as usize * h as usize, encoding);
        match &img {
            DynamicImage::ImageLuma8(i) => {
                acc.add(i.as_raw(), 1, 8, |v| v as f32 / 255.0, |v| v == u8::MAX)
            }
            DynamicImage::ImageLumaA8(i) => {
                acc.add(i.as_raw(), 2, 8, |v| v as f32 / 255.0, |v| v == u8::MAX)
            }
            DynamicImage::ImageRgb8(i) => {
                acc.add(i.as_raw(), 3, 8, |v| v as f32 / 255.0, |v| v == u8::MAX)
            }
            DynamicImage::ImageRgba8(i) => {
                acc.add(i.as_raw(), 4, 8, |v| v as f32 / 255.0, |v| v == u8::MAX)
            }
            DynamicImage::ImageLuma16(i) => acc.add(i.as_raw(), 1, 16, unit16, |v| v == u16::MAX),
            DynamicImage::ImageLumaA16(i) => acc.add(i.as_raw(), 2, 16, unit16, |v| v == u16::MAX),
            DynamicImage::ImageRgb16(i) => acc.add(i.as_raw(), 3, 16, unit16, |v| v == u16::MAX),
            DynamicImage::ImageRgba16(i) => acc.add(i.as_raw(), 4, 16, unit16, |v| v == u16::MAX),
            DynamicImage::ImageRgb32F(i) => acc.add(i.as_raw(), 3, 32, |v| v, |_| false),
            DynamicImage::ImageRgba32F(i) => acc.add(i.as_raw(), 4, 32, |v| v, |_| false),
            // A layout added to the image crate later: through float, with
            // no maximum known.
            other => acc.add(other.to_rgb32f().as_raw(), 3, 32, |v| v, |_| false),
        }
        acc.finish(w, h)
    }

    /// True when `levels` say nothing `image` does not: an 8-bit sRGB file.
    pub fn is_plain(&self) -> bool {
        self.bits == 8 && self.encoding == Encoding::Srgb
    }
}

fn unit16(v: u16) -> f32 {
    v as f32 / 65535.0
}

/// Builds a photo's levels and saturated list pixel by pixel.
struct Accumulator {
    encoding: Encoding,
    levels: Vec<f32>,
    saturated: Vec<u32>,
    non_finite: Vec<u32>,
    bits: u8,
}

impl Accumulator {
    fn new(pixels: usize, encoding: Encoding) -> Self {
        Accumulator {
            encoding,
            levels: Vec::with_capacity(pixels * 3),
            saturated: Vec::new(),
            non_finite: Vec::new(),
            bits: 8,
        }
    }

    /// `raw` holds `channels` values per pixel (1 or 2: grey, alpha; 3 or
    /// 4: red, green, blue, alpha); `unit` maps a value to 0..1 at the
    /// format's maximum, `at_max` says whether it is that maximum.
    fn add<T: Copy>(
        &mut self,
        raw: &[T],
        channels: usize,
        bits: u8,
        unit: impl Fn(T) -> f32,
        at_max: impl Fn(T) -> bool,
    ) {
        self.bits = bits;
        let colour = if channels < 3 { 1 } else { 3 };
        for (i, px) in raw.chunks_exact(channels).enumerate() {
            let px = &px[..colour];
            if px.iter().any(|&v| at_max(v)) {
                self.saturated.push(i as u32);
            }
            // NaN or Inf (only a float file has them): level 0, and listed
            // so that the fit leaves the pixel out rather than see black
            let finite = px.iter().all(|&v| unit(v).is_finite());
            if !finite {
                self.non_finite.push(i as u32);
            }
            for c in 0..3 {
                let v = unit(px[c.min(colour - 1)]);
                let level = if finite {
                    self.encoding.to_srgb(v) * 255.0
                } else {
                    0.0
                };
                self.levels.push(level);
            }
        }
    }

    fn finish(self, width: u32, height: u32) -> Photo {
        let bytes = self.levels.iter().map(|l| l.round() as u8).collect();
        let image = Image::from_raw(width, height, bytes)
            .expect("three levels per pixel of the decoded image");
        Photo {
            image,
            levels: self.levels,
            saturated: self.saturated,
            non_finite: self.non_finite,
            encoding: self.encoding,
            bits: self.bits,
        }
    }
}

/// Where a mask counts: its luma above half the format's maximum (any
/// depth), as pixel indices.
pub fn mask_pixels(img: &DynamicImage) -> Vec<u32> {
    fn above<T: Copy + PartialOrd>(raw: &[T], half: T) -> Vec<u32> {
        raw.iter()
            .enumerate()
            .filter(|(_, &v)| v > half)
            .map(|(i, _)| i as u32)
            .collect()
    }
    match img {
        DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_) => above(img.to_luma8().as_raw(), 127u8),
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => above(img.to_luma16().as_raw(), 32767u16),
        _ => above(img.to_luma32f().as_raw(), 0.5f32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_levels_keep_what_eight_bits_round() {
        // 16-bit 32896 is 8-bit level 128.0 exactly; 33000 is 128.40.
        let img = image::ImageBuffer::from_raw(2, 1, vec![32896u16, 33000, 0, 65535, 65535, 65535])
            .unwrap();
        let p = Photo::from_decoded(DynamicImage::ImageRgb16(img), Encoding::Srgb);
        assert_eq!(p.bits, 16);
        assert!((p.levels[0] - 128.0).abs() < 1e-3);
        assert!((p.levels[1] - 128.404).abs() < 1e-2);
        assert_eq!(p.image.get_pixel(0, 0).0, [128, 128, 0]);
        assert_eq!(p.saturated, vec![1]);
        assert!(!p.is_plain());
    }

    #[test]
    fn grey_is_three_equal_channels_and_linear_goes_through_srgb() {
        let img = image::ImageBuffer::from_raw(
            2,
            1,
            vec![0.214_041f32, 0.214_041, 0.214_041, 2.0, 2.0, 2.0],
        )
        .unwrap();
        let p = Photo::from_decoded(DynamicImage::ImageRgb32F(img), Encoding::Linear);
        assert!((p.levels[0] - 127.5).abs() < 0.05, "{}", p.levels[0]);
        // Above 1 is clipped, and float has no maximum: nothing saturated.
        assert_eq!(p.image.get_pixel(1, 0).0, [255, 255, 255]);
        assert!(p.saturated.is_empty());
        let grey = image::GrayImage::from_raw(1, 1, vec![255]).unwrap();
        let p = Photo::from_decoded(DynamicImage::ImageLuma8(grey), Encoding::Srgb);
        assert_eq!(p.image.get_pixel(0, 0).0, [255, 255, 255]);
        assert_eq!(p.saturated, vec![0]);
        assert!(p.is_plain());
    }

    #[test]
    fn nan_and_inf_are_listed_and_read_as_zero() {
        let img = image::ImageBuffer::from_raw(
            3,
            1,
            vec![
                0.5f32,
                0.5,
                0.5,
                f32::NAN,
                0.5,
                0.5,
                0.5,
                f32::INFINITY,
                0.5,
            ],
        )
        .unwrap();
        let p = Photo::from_decoded(DynamicImage::ImageRgb32F(img), Encoding::Linear);
        assert_eq!(p.non_finite, vec![1, 2]);
        assert!(p.levels.iter().all(|l| l.is_finite()));
        assert_eq!(&p.levels[3..9], &[0.0; 6]);
        assert!(p.levels[0] > 100.0);
    }

    #[test]
    fn masks_count_above_half_at_any_depth() {
        let m16 = image::ImageBuffer::from_raw(3, 1, vec![0u16, 32767, 32768]).unwrap();
        assert_eq!(mask_pixels(&DynamicImage::ImageLuma16(m16)), vec![2]);
        let m8 = image::GrayImage::from_raw(3, 1, vec![127, 128, 255]).unwrap();
        assert_eq!(mask_pixels(&DynamicImage::ImageLuma8(m8)), vec![1, 2]);
    }
}
