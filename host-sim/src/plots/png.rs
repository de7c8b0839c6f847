//! PNG beside every SVG plot, rendered in-process with resvg (no external tool at run
//! time), so a report reads in any image viewer. Text is set in the system's sans-serif
//! face (DejaVu Sans, Liberation Sans, Noto Sans, Arial or Helvetica, whichever is found
//! first; fontdb reads the system's font folders once per process, and maps a face's file
//! each time text is set in it rather than reading the whole file again).

use resvg::tiny_skia::{Pixmap, Transform};
use resvg::usvg::{self, fontdb};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Sans-serif families tried in order for the plots' `sans-serif` text.
const SANS: [&str; 5] = [
    "DejaVu Sans",
    "Liberation Sans",
    "Noto Sans",
    "Arial",
    "Helvetica",
];

/// The system's fonts, loaded once, with `sans-serif` mapped to a face that exists.
fn fonts() -> Arc<fontdb::Database> {
    static FONTS: OnceLock<Arc<fontdb::Database>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            let mut db = fontdb::Database::new();
            db.load_system_fonts();
            let families: Vec<String> = db
                .faces()
                .flat_map(|f| f.families.iter().map(|(n, _)| n.clone()))
                .collect();
            let sans = SANS
                .iter()
                .find(|s| families.iter().any(|f| f == *s))
                .map(|s| s.to_string())
                .or_else(|| families.first().cloned());
            if let Some(s) = sans {
                db.set_sans_serif_family(s);
            }
            Arc::new(db)
        })
        .clone()
}

/// The PNG's path beside an SVG (`x.svg` → `x.png`).
pub fn beside(svg: &Path) -> PathBuf {
    svg.with_extension("png")
}

/// Renders the SVG `text` to a PNG of the same pixel size.
pub fn render(text: &str) -> Result<Vec<u8>, String> {
    let options = usvg::Options {
        fontdb: fonts(),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_data(text.as_bytes(), &options).map_err(|e| format!("SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("an image of {}x{} pixels", size.width(), size.height()))?;
    resvg::render(&tree, Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| format!("PNG: {e}"))
}
