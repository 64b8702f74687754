//! Writing a figure to disk: the format follows the extension (`.svg` or `.png`), the file
//! is written atomically, and the font is embedded (DejaVu Sans, registered once) so that
//! PNG text renders the same on every machine without system fonts.

use facette_bsdf::storage::atomic_file::write_atomically;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;
use thiserror::Error;

/// Errors of the plotting module.
#[derive(Debug, Error)]
pub enum PlotError {
    #[error("{path}: unknown figure format; use a .svg or .png extension")]
    UnknownFormat { path: PathBuf },
    #[error("cannot draw the figure: {0}")]
    Draw(String),
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{0}")]
    Data(String),
}

/// Something drawable on any plotters backend.
pub trait Figure {
    /// Size in pixels (SVG user units).
    fn size(&self) -> (u32, u32);
    /// Draws onto `root` (already cleared to white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// The output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    /// The format named by a path's extension.
    pub fn of(path: &Path) -> Result<Format, PlotError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref()
        {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(PlotError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

static FONTS: Once = Once::new();

/// Registers the embedded font under the family names plotters uses.
pub fn register_fonts() {
    FONTS.call_once(|| {
        let regular = dejavu::sans::regular();
        let bold = dejavu::sans::bold();
        let oblique = dejavu::sans::oblique();
        for family in ["sans-serif", "serif", "DejaVu Sans"] {
            // The embedded font is valid TrueType: registration cannot fail.
            let _ = plotters::style::register_font(family, FontStyle::Normal, regular);
            let _ = plotters::style::register_font(family, FontStyle::Bold, bold);
            let _ = plotters::style::register_font(family, FontStyle::Oblique, oblique);
            let _ = plotters::style::register_font(family, FontStyle::Italic, oblique);
        }
    });
}

pub(crate) fn draw_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// Renders a figure to bytes in the given format.
pub fn render_figure<F: Figure>(fig: &F, format: Format) -> Result<Vec<u8>, PlotError> {
    register_fonts();
    let (w, h) = fig.size();
    match format {
        Format::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                fig.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            Ok(s.into_bytes())
        }
        Format::Png => {
            let mut buf = vec![255u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                fig.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            encode_png(&buf, w, h)
        }
    }
}

/// RGB8 pixels to a PNG file's bytes.
fn encode_png(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, PlotError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::High);
        let mut writer = enc.write_header().map_err(draw_err)?;
        writer.write_image_data(rgb).map_err(draw_err)?;
    }
    Ok(out)
}

/// Draws a figure into `path` (.svg or .png), atomically.
pub fn save_figure<F: Figure>(fig: &F, path: &Path) -> Result<(), PlotError> {
    let format = Format::of(path)?;
    let bytes = render_figure(fig, format)?;
    write_atomically(path, &bytes).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}
