//! Writing the GIF: one global palette holding every colour drawn exactly (anti-aliased
//! blends take the nearest of a grey ramp and a colour cube), each frame stored as the
//! rectangle that changed since the one before (unchanged pixels transparent, frames
//! kept), looping forever. Written beside the target and renamed over it, so a reader
//! never sees half a GIF.

use std::borrow::Cow;
use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{CliError, CliResult, io_failed};
use crate::interrupt::Partial;

/// The palette index left transparent (pixels unchanged since the previous frame).
const CLEAR: u8 = 255;

/// The colours of the GIF and a memo of which index each RGB value maps to.
struct Palette {
    colours: Vec<[u8; 3]>,
    memo: HashMap<[u8; 3], u8>,
}

impl Palette {
    /// `exact` first, then 16 greys and a 6 × 6 × 6 colour cube, without repeats.
    fn new(exact: &[[u8; 3]]) -> Self {
        let mut colours: Vec<[u8; 3]> = Vec::new();
        let greys = (0..16u8).map(|k| [17 * k; 3]);
        let cube = (0..216u8).map(|k| [51 * (k / 36), 51 * (k / 6 % 6), 51 * (k % 6)]);
        for c in exact.iter().copied().chain(greys).chain(cube) {
            if !colours.contains(&c) && colours.len() < usize::from(CLEAR) {
                colours.push(c);
            }
        }
        Self { colours, memo: HashMap::new() }
    }

    /// The index of the colour nearest `c`.
    fn index(&mut self, c: [u8; 3]) -> u8 {
        let colours = &self.colours;
        *self.memo.entry(c).or_insert_with(|| {
            let distance = |p: &[u8; 3]| {
                let d = |k: usize| i32::from(p[k]) - i32::from(c[k]);
                3 * d(0) * d(0) + 4 * d(1) * d(1) + 2 * d(2) * d(2)
            };
            let (best, _) = colours.iter().enumerate().min_by_key(|(_, p)| distance(p)).expect("colours");
            best as u8
        })
    }

    /// The 256 entries as r, g, b bytes.
    fn bytes(&self) -> Vec<u8> {
        let mut bytes: Vec<u8> = self.colours.iter().flatten().copied().collect();
        bytes.resize(256 * 3, 255);
        bytes
    }
}

/// An animated GIF being written.
pub struct GifFile {
    encoder: Option<gif::Encoder<BufWriter<File>>>,
    /// Where the frames go until [`GifFile::finish`] renames it to `path`.
    partial: PathBuf,
    /// Removes `partial` if Ctrl-C ends the process.
    _registered: Partial,
    path: PathBuf,
    size: usize,
    palette: Palette,
    /// The picture shown so far (RGB).
    shown: Vec<u8>,
    indices: Vec<u8>,
    /// Frames written.
    pub frames: usize,
}

impl GifFile {
    /// Starts a GIF of `size × size` px at `path`; `colours` are the colours drawn.
    pub fn create(path: &Path, size: u32, colours: &[[u8; 3]]) -> CliResult<Self> {
        let mut name = path.file_name().unwrap_or_default().to_os_string();
        name.push(".partial");
        let partial = path.with_file_name(name);
        let registered = Partial::register(&partial);
        let file = File::create(&partial).map_err(|e| io_failed("create", &partial, e))?;
        let palette = Palette::new(colours);
        let side = size as u16;
        let fail =
            |e: gif::EncodingError| CliError::failed(format!("cannot write {}: {e}", partial.display()));
        let mut encoder =
            gif::Encoder::new(BufWriter::new(file), side, side, &palette.bytes()).map_err(fail)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(fail)?;
        Ok(Self {
            encoder: Some(encoder),
            partial,
            _registered: registered,
            path: path.to_path_buf(),
            size: size as usize,
            palette,
            shown: Vec::new(),
            indices: Vec::new(),
            frames: 0,
        })
    }

    /// Adds a frame (`rgb`: `size × size` pixels, row by row) shown for `delay`
    /// centiseconds.
    pub fn frame(&mut self, rgb: &[u8], delay: u16) -> CliResult<()> {
        let w = self.size;
        let changed = if self.shown.is_empty() { Some((0, 0, w, w)) } else { changed(&self.shown, rgb, w) };
        // Nothing changed: one transparent pixel holds the time.
        let (left, top, right, bottom) = changed.unwrap_or((0, 0, 1, 1));
        self.indices.clear();
        // Runs of one colour (the background, mostly) skip the palette's lookup.
        let mut last: Option<([u8; 3], u8)> = None;
        let first = self.shown.is_empty();
        for y in top..bottom {
            let span = 3 * (y * w + left)..3 * (y * w + right);
            let row = &rgb[span.clone()];
            let old = if first { row } else { &self.shown[span] };
            for (pixel, before) in row.chunks_exact(3).zip(old.chunks_exact(3)) {
                let c = [pixel[0], pixel[1], pixel[2]];
                let index = if changed.is_none() || (!first && pixel == before) {
                    CLEAR
                } else {
                    match last {
                        Some((colour, index)) if colour == c => index,
                        _ => {
                            let index = self.palette.index(c);
                            last = Some((c, index));
                            index
                        }
                    }
                };
                self.indices.push(index);
            }
        }
        let frame = gif::Frame {
            delay,
            dispose: gif::DisposalMethod::Keep,
            transparent: (self.frames > 0).then_some(CLEAR),
            left: left as u16,
            top: top as u16,
            width: (right - left) as u16,
            height: (bottom - top) as u16,
            buffer: Cow::Borrowed(&self.indices),
            ..gif::Frame::default()
        };
        let encoder = self.encoder.as_mut().expect("open until finished");
        encoder
            .write_frame(&frame)
            .map_err(|e| CliError::failed(format!("cannot write {}: {e}", self.partial.display())))?;
        self.shown.clear();
        self.shown.extend_from_slice(rgb);
        self.frames += 1;
        Ok(())
    }

    /// Ends the GIF and moves it to its path.
    pub fn finish(mut self) -> CliResult<()> {
        let encoder = self.encoder.take().expect("open until finished");
        let mut writer = encoder.into_inner().map_err(|e| io_failed("write", &self.partial, e))?;
        writer.flush().map_err(|e| io_failed("write", &self.partial, e))?;
        writer.get_ref().sync_all().map_err(|e| io_failed("sync", &self.partial, e))?;
        drop(writer);
        std::fs::rename(&self.partial, &self.path).map_err(|e| io_failed("rename into", &self.path, e))
    }
}

impl Drop for GifFile {
    /// A GIF abandoned before [`GifFile::finish`] leaves no partial file.
    fn drop(&mut self) {
        if self.encoder.take().is_some() {
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

/// The rectangle (left, top, right, bottom; right and bottom exclusive) of the pixels
/// that differ between `a` and `b` (RGB, `w` px wide), or `None`.
fn changed(a: &[u8], b: &[u8], w: usize) -> Option<(usize, usize, usize, usize)> {
    let row = 3 * w;
    let mut rect: Option<(usize, usize, usize, usize)> = None;
    for (y, (ra, rb)) in a.chunks_exact(row).zip(b.chunks_exact(row)).enumerate() {
        if ra == rb {
            continue;
        }
        let first = ra.chunks_exact(3).zip(rb.chunks_exact(3)).position(|(p, q)| p != q).unwrap_or(0);
        let last =
            w - ra.chunks_exact(3).rev().zip(rb.chunks_exact(3).rev()).position(|(p, q)| p != q).unwrap_or(0);
        rect = Some(match rect {
            None => (first, y, last, y + 1),
            Some((l, t, r, _)) => (l.min(first), t, r.max(last), y + 1),
        });
    }
    rect
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_changed_rectangle_is_tight() {
        let w = 5;
        let a = vec![0u8; 3 * w * 4];
        let mut b = a.clone();
        b[3 * (w + 1)] = 9; // (1, 1)
        b[3 * (2 * w + 3) + 2] = 9; // (3, 2)
        assert_eq!(changed(&a, &b, w), Some((1, 1, 4, 3)));
        assert_eq!(changed(&a, &a, w), None);
    }

    #[test]
    fn exact_colours_map_to_themselves() {
        let mut palette = Palette::new(&[[20, 60, 220], [255, 255, 255]]);
        assert!(palette.colours.len() <= 255);
        assert_eq!(palette.index([20, 60, 220]), 0);
        assert_eq!(palette.index([255, 255, 255]), 1);
        let grey = palette.index([120, 120, 121]) as usize;
        assert_eq!(palette.colours[grey], [119, 119, 119]);
    }
}
