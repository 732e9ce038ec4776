//! PNG renderings of the SVG plots, drawn by resvg (pure Rust, no system library) with an
//! embedded font, so that the text renders the same on a machine without fonts.
//!
//! The font is a subset of DejaVu Sans (Latin, Greek, punctuation, super- and subscripts,
//! some mathematical signs; licence in `src/io/fonts/LICENSE`), registered as the database's
//! sans-serif family; system fonts are never loaded.
//!
//! Resolution: the plots are drawn in CSS pixels (96 per inch), so a 960 px wide plot is a
//! 10 in figure; [`PNG_DPI`] = 300 renders it 3000 px wide and records 300 dpi in the PNG's
//! `pHYs` chunk.

use std::sync::{Arc, OnceLock};

use resvg::{tiny_skia, usvg};

/// The embedded font (a DejaVu Sans subset).
const FONT: &[u8] = include_bytes!("fonts/DejaVuSans-subset.ttf");

/// Resolution of the PNG files, in dots per inch at the plot's nominal size.
pub const PNG_DPI: f32 = 300.0;

/// Pixels per inch of the SVG plots (CSS pixels).
const SVG_DPI: f32 = 96.0;

/// Why a plot could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The SVG did not parse.
    #[error("the SVG does not parse: {0}")]
    Parse(#[from] usvg::Error),
    /// The image size is zero or too large.
    #[error("cannot make a {width} × {height} px image")]
    Size {
        /// Width (px).
        width: u32,
        /// Height (px).
        height: u32,
    },
    /// PNG encoding failed.
    #[error("cannot encode the PNG: {0}")]
    Encode(String),
}

/// The parse options with the embedded font as the only font (built once).
fn options() -> &'static usvg::Options<'static> {
    static OPTIONS: OnceLock<usvg::Options<'static>> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT.to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        usvg::Options {
            font_family: "DejaVu Sans".into(),
            fontdb: Arc::new(db),
            ..usvg::Options::default()
        }
    })
}

/// Render an SVG document to PNG bytes at [`PNG_DPI`].
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, RenderError> {
    let tree = usvg::Tree::from_str(svg, options())?;
    let scale = PNG_DPI / SVG_DPI;
    let size = tree.size();
    let (width, height) = (
        (size.width() * scale).round() as u32,
        (size.height() * scale).round() as u32,
    );
    let mut pixmap =
        tiny_skia::Pixmap::new(width, height).ok_or(RenderError::Size { width, height })?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    let png = pixmap
        .encode_png()
        .map_err(|e| RenderError::Encode(e.to_string()))?;
    Ok(with_resolution(png, PNG_DPI))
}

/// The PNG with a `pHYs` chunk (pixels per metre) after its header chunk.
fn with_resolution(png: Vec<u8>, dpi: f32) -> Vec<u8> {
    // 8-byte signature, then IHDR: 4 length + 4 type + 13 data + 4 CRC.
    const IHDR_END: usize = 8 + 4 + 4 + 13 + 4;
    if png.len() < IHDR_END || &png[12..16] != b"IHDR" {
        return png;
    }
    let per_metre = (dpi as f64 / 0.0254).round() as u32;
    let mut chunk = b"pHYs".to_vec();
    chunk.extend(per_metre.to_be_bytes());
    chunk.extend(per_metre.to_be_bytes());
    chunk.push(1); // unit: the metre
    let mut out = png[..IHDR_END].to_vec();
    out.extend(9u32.to_be_bytes());
    out.extend(&chunk);
    out.extend(crc32(&chunk).to_be_bytes());
    out.extend(&png[IHDR_END..]);
    out
}

/// CRC-32 (ISO 3309, as PNG uses it).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// The width and height (px) of a PNG, from its header; `None` if it is not a PNG.
#[cfg(any(test, feature = "internals"))]
pub fn png_size(png: &[u8]) -> Option<(u32, u32)> {
    let header = png.get(..24)?;
    (&header[..8] == b"\x89PNG\r\n\x1a\n" && &header[12..16] == b"IHDR").then(|| {
        let be = |r: std::ops::Range<usize>| {
            u32::from_be_bytes(header[r].try_into().expect("four bytes"))
        };
        (be(16..20), be(20..24))
    })
}

/// The files of one plot: `plots/<name>.svg`, and `plots/<name>.png` when `png` is set.
pub(crate) fn plot_files(
    name: &str,
    svg: &str,
    png: bool,
) -> Result<Vec<(String, Vec<u8>)>, crate::error::Error> {
    let mut files = vec![(format!("plots/{name}.svg"), svg.as_bytes().to_vec())];
    if png {
        let path = format!("plots/{name}.png");
        let bytes = svg_to_png(svg).map_err(|e| crate::error::Error::WriteOutput {
            path: path.clone().into(),
            source: std::io::Error::other(e),
        })?;
        files.push((path, bytes));
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_of_the_check_string() {
        assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
    }

    #[test]
    fn a_plot_renders_at_300_dpi_with_its_text_and_decodes() {
        let svg = crate::io::svg::line_plot(
            "q/(ηp0) against x/a",
            "x/a",
            "σxx/p0",
            &[crate::io::svg::Series {
                label: "",
                points: vec![(0.0, 0.0), (1.0, 1.0)],
                colour: "black",
            }],
        );
        let png = svg_to_png(&svg).unwrap();
        assert_eq!(png_size(&png), Some((3000, 1375)));
        let pixmap = tiny_skia::Pixmap::decode_png(&png).unwrap();
        assert_eq!((pixmap.width(), pixmap.height()), (3000, 1375));
        // The title's glyphs are drawn (dark pixels in the title's row band): the font loaded.
        let title_row_dark = (40..80)
            .any(|y| (1000..2000).any(|x| pixmap.pixel(x, y).is_some_and(|p| p.red() < 128)));
        assert!(
            title_row_dark,
            "no text drawn: the embedded font did not load"
        );
        // 300 dpi = 11811 px/m in the pHYs chunk.
        let at = png.windows(4).position(|w| w == b"pHYs").unwrap();
        assert_eq!(&png[at + 4..at + 8], &11811u32.to_be_bytes());
    }
}
