//! The plan drawn a strip of rows at a time: every strip is drawn from the shapes that cross
//! it alone, so the strips of a build are drawn in parallel, and the workbench (issue 61),
//! which keeps the image it drew before with each strip's key, draws again only the strips
//! whose shapes changed. One lot's edit redraws one or two strips of twenty.
//!
//! A strip's key hashes, in drawing order, each layer's start and each shape it takes with
//! the look of its batch ([`super::paint::Batch`]): equal keys mean equal calls to
//! tiny-skia into equal pixels. Whether a strip takes a shape is decided by [`crosses`]
//! alone, both when the keys are made and when the strip is drawn, so a key always names
//! what its strip draws.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;
use sha2::{Digest, Sha256};
use tiny_skia::{Color, Pixmap, PixmapMut};

/// Rows of pixels in a strip: the plan of a town is 2400 pixels at most on its longer side,
/// so about twenty strips; each goes through every shape to find its own.
pub const STRIP_ROWS: u32 = 128;

/// The plan's paper.
pub(super) const BACKGROUND: [u8; 3] = [250, 248, 242];

/// Where the shapes of the layers go.
pub(super) enum Target<'a> {
    /// Drawn into the image's rows from `top` (a strip of [`STRIP_ROWS`], the last one
    /// shorter), which `pm` holds.
    Draw { pm: PixmapMut<'a>, top: u32 },
    /// Hashed into the key of each strip they cross.
    Keys(Vec<Sha256>),
}

impl<'a> Target<'a> {
    /// Marks the start of a layer (in the keys: a shape of a layer drawn after another is
    /// drawn over it, whatever its look).
    pub(super) fn layer(&mut self, name: &str) {
        if let Target::Keys(keys) = self {
            for key in keys {
                key.update(name.as_bytes());
                key.update([0xff]);
            }
        }
    }

    /// Whether a shape whose ink is within `rows` (image pixels, top and bottom) is
    /// drawn here or, for the keys, crosses the image.
    pub(super) fn wants(&self, rows: (f32, f32)) -> bool {
        match self {
            Target::Draw { top, .. } => crosses(rows, *top, STRIP_ROWS),
            Target::Keys(keys) => crosses(rows, 0, STRIP_ROWS * keys.len() as u32),
        }
    }

    /// Takes the shape of `points` (of a batch of `look`, its ink within `rows`), which
    /// [`Self::wants`]: a drawn strip answers how far up to move it (its top row); keys
    /// hash it into each strip it crosses and answer none.
    pub(super) fn take(
        &mut self,
        rows: (f32, f32),
        look: &[u8],
        kind: u8,
        points: &[(f32, f32)],
    ) -> Option<f32> {
        let keys = match self {
            Target::Draw { top, .. } => return Some(*top as f32),
            Target::Keys(keys) => keys,
        };
        let height = STRIP_ROWS;
        let strips = keys.len() as u32;
        // The strips a shape may cross, each then asked exactly as a drawn strip asks.
        let first = (rows.0 / height as f32).floor().max(0.0) as u32;
        let last = ((rows.1 / height as f32).floor().max(0.0) as u32).min(strips - 1);
        for s in first.min(strips)..=last {
            if crosses(rows, s * height, height) {
                let key = &mut keys[s as usize];
                key.update(look);
                key.update([kind]);
                key.update((points.len() as u32).to_le_bytes());
                for (x, y) in points {
                    key.update(x.to_le_bytes());
                    key.update(y.to_le_bytes());
                }
            }
        }
        None
    }

    /// Where a batch's paths (moved to this strip's rows) are drawn; keys draw none.
    pub(super) fn pixmap(&mut self) -> Option<&mut PixmapMut<'a>> {
        match self {
            Target::Draw { pm, .. } => Some(pm),
            Target::Keys(_) => None,
        }
    }
}

/// Whether ink within `rows` (image pixels, top and bottom) reaches the strip of `height`
/// rows from `top`.
fn crosses(rows: (f32, f32), top: u32, height: u32) -> bool {
    rows.1 >= top as f32 && rows.0 < (top + height) as f32
}

/// The plan as drawn before, without what is drawn over it (tile grid, scale bar, legend):
/// kept by the workbench from one rebuild to the next.
#[derive(Debug, Default)]
pub struct Kept {
    canvas: Mutex<Option<Canvas>>,
    /// How many strips the last image drawn with it took as they were.
    strips_kept: AtomicUsize,
}

impl Kept {
    /// How many strips the last image drawn with it took from the image before.
    pub fn strips_kept(&self) -> usize {
        self.strips_kept.load(Ordering::Relaxed)
    }
}

#[derive(Debug)]
struct Canvas {
    pixels: Pixmap,
    keys: Vec<[u8; 32]>,
}

/// The image `width` x `height` of what `layers` draws, strip by strip on every core; with
/// `kept`, the strips whose keys are those of the image kept stay as they are in it, and the
/// image is kept for the next.
pub(super) fn draw(
    width: u32,
    height: u32,
    layers: &(dyn Fn(&mut Target) + Sync),
    kept: Option<&Kept>,
) -> Option<Pixmap> {
    let strips = height.div_ceil(STRIP_ROWS);
    let Some(kept) = kept else {
        let mut pm = Pixmap::new(width, height)?;
        draw_strips(&mut pm, layers, &vec![true; strips as usize]);
        return Some(pm);
    };
    let keys = strip_keys(strips, layers);
    let mut memory = kept.canvas.lock().unwrap_or_else(|e| e.into_inner());
    let (mut pm, redraw) = match memory.take() {
        Some(c) if (c.pixels.width(), c.pixels.height()) == (width, height) => {
            let redraw = keys.iter().zip(&c.keys).map(|(a, b)| a != b).collect();
            (c.pixels, redraw)
        }
        _ => (Pixmap::new(width, height)?, vec![true; strips as usize]),
    };
    draw_strips(&mut pm, layers, &redraw);
    let same = redraw.iter().filter(|&&again| !again).count();
    kept.strips_kept.store(same, Ordering::Relaxed);
    let image = pm.clone();
    *memory = Some(Canvas { pixels: pm, keys });
    Some(image)
}

/// Each strip's key: one pass through the layers.
pub(super) fn strip_keys(strips: u32, layers: &(dyn Fn(&mut Target) + Sync)) -> Vec<[u8; 32]> {
    let mut t = Target::Keys(vec![Sha256::new(); strips as usize]);
    layers(&mut t);
    match t {
        Target::Keys(keys) => keys.into_iter().map(|k| k.finalize().into()).collect(),
        Target::Draw { .. } => Vec::new(),
    }
}

/// Paints the strips `redraw` names: the paper, then the layers, strips on every core.
fn draw_strips(pm: &mut Pixmap, layers: &(dyn Fn(&mut Target) + Sync), redraw: &[bool]) {
    let width = pm.width();
    let stride = width as usize * 4 * STRIP_ROWS as usize;
    let paper = Color::from_rgba8(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 255);
    pm.data_mut()
        .par_chunks_mut(stride)
        .zip(redraw)
        .enumerate()
        .filter(|(_, (_, &again))| again)
        .for_each(|(s, (rows, _))| {
            let height = (rows.len() / (width as usize * 4)) as u32;
            if let Some(mut pm) = PixmapMut::from_bytes(rows, width, height) {
                pm.fill(paper);
                let top = s as u32 * STRIP_ROWS;
                layers(&mut Target::Draw { pm, top });
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_on_a_strips_edge_belongs_to_both() {
        assert!(crosses((100.0, 130.0), 0, 128));
        assert!(crosses((100.0, 130.0), 128, 128));
        assert!(!crosses((100.0, 127.0), 128, 128));
        assert!(!crosses((128.0, 140.0), 0, 128));
    }
}
