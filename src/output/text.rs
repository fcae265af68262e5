//! Text on plan images, from the public-domain 8x8 bitmap font: tile ids, legend, scale bar.
//! (tiny-skia draws no text; a bitmap font needs no font file on the machine.)

use font8x8::UnicodeFonts;
use tiny_skia::{Paint, Pixmap, Rect, Transform};

/// Width in pixels of `text` drawn at `scale` (each glyph is 8 x scale pixels).
pub fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * 8 * scale
}

/// Draws `text` with its top-left corner at (x, y). Characters the font lacks show as `?`.
pub fn draw_text(pm: &mut Pixmap, x: f32, y: f32, text: &str, scale: u32, rgb: [u8; 3]) {
    let mut paint = Paint::default();
    paint.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    paint.anti_alias = false;
    let s = scale as f32;
    for (i, ch) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS
            .get(ch)
            .or_else(|| font8x8::BASIC_FONTS.get('?'))
            .unwrap_or([0; 8]);
        let gx = x + i as f32 * 8.0 * s;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) != 0 {
                    if let Some(r) = Rect::from_xywh(gx + col as f32 * s, y + row as f32 * s, s, s)
                    {
                        pm.fill_rect(r, &paint, Transform::identity(), None);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_puts_ink_where_it_is_drawn() {
        let mut pm = Pixmap::new(40, 20).unwrap();
        draw_text(&mut pm, 2.0, 2.0, "12", 1, [0, 0, 0]);
        let inked = pm.pixels().iter().filter(|p| p.alpha() > 0).count();
        assert!(inked > 10, "{inked}");
        assert_eq!(text_width("12_7", 2), 64);
    }
}
