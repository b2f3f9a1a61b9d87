//! A sample to scan, read from a TOML file: its materials (each any of `tap`'s sample
//! and law parameters over the run's own) and their layout: stripes along the scan line
//! (x) that run across the image (y), and discs laid over them.
//!
//! ```toml
//! length = "1um"               # the scan line
//! width = "1um"                # the image's extent in y (default: the length)
//! [[material]]
//! name = "A"
//! sample-modulus = "0.5GPa"
//! work-of-adhesion = 0.1
//! [[material]]
//! name = "B"
//! sample-modulus = "1GPa"
//! [[region]]                   # from the end of the last region (or 0)
//! until = "0.5um"              # to here,
//! material = "A"               # this material,
//! height = "0nm"               # its surface this high (default 0)
//! [[region]]
//! until = "1um"
//! material = "B"
//! [[disc]]                     # over the stripes
//! x = "250nm"                  # centre,
//! y = "500nm"
//! radius = "150nm"
//! material = "B"
//! height = "0nm"               # (default 0)
//! ```
//!
//! `mask = "mask.csv"` (beside the sample file) lays a grid of cells over the stripes
//! and under the discs: a CSV of material names, the first row the top of the image,
//! cells spanning length/columns × width/rows, each `B` or `B@1nm` (with a surface
//! height), an empty cell showing what lies beneath.
//!
//! `mask = "mask.png"` gives the grid as an image instead, one cell a pixel, its colours
//! named in a table (a pixel of any other colour, or partly transparent, is refused;
//! a transparent one shows what lies beneath):
//!
//! ```toml
//! mask = "mask.png"
//! [mask-colours]
//! "#000000" = "A"
//! "#ff0000" = "B@1nm"
//! ```

use crate::app::config::{MAX_CONFIG_BYTES, TapInputs, read_input, read_text};

/// A TOML value of a sample file as text ([`crate::app::config::value_text`]).
fn value_text(value: &toml::Value, key: &str) -> Result<String> {
    crate::app::config::value_text(value, key, "sample value")
}
use crate::dynamics::setup::TapSetup;
use crate::error::{Error, Result};
use crate::instrument::scan::{Disc, Layout, Mask, Region};
use std::path::Path;

/// The most materials and regions a sample holds.
pub const MAX_MATERIALS: usize = 64;
/// The most regions along a line.
pub const MAX_REGIONS: usize = 10_000;
/// The most discs.
pub const MAX_DISCS: usize = 1_000;

/// A sample: named materials over a common cantilever, and their layout.
#[derive(Debug, Clone)]
pub struct Sample {
    /// The line's length in m.
    pub length_m: f64,
    /// The image's extent across the lines (y) in m.
    pub width_m: f64,
    /// Each material's name and setup.
    pub materials: Vec<(String, TapSetup)>,
    /// The layout in the plane.
    pub layout: Layout,
}

/// The built-in sample: a flat blend of the two polymers `contrast` compares, A
/// (E = 0.5 GPa, Δγ = 0.1 J/m², the defaults) on the first half of a 1 µm line and B
/// (E = 1 GPa, Δγ = 0.08 J/m²) on the second.
pub const BLEND: &str = r#"
length = "1um"
[[material]]
name = "A"
sample-modulus = "0.5GPa"
work-of-adhesion = 0.1
[[material]]
name = "B"
sample-modulus = "1GPa"
work-of-adhesion = 0.08
[[region]]
until = "0.5um"
material = "A"
[[region]]
until = "1um"
material = "B"
"#;

/// The shortest line and narrowest image a sample may describe, in m (a few atoms).
pub const MIN_SIZE_M: f64 = 1e-9;
/// The longest line and widest image, in m: a millimetre, ten times an AFM's largest
/// scanner.
pub const MAX_SIZE_M: f64 = 1e-3;

impl Sample {
    /// Read a sample file (at most [`MAX_CONFIG_BYTES`]), each material over `base`; a
    /// mask it names is read from beside it.
    pub fn from_file(path: &Path, base: &TapInputs) -> Result<Self> {
        let refuse = |reason: String| Error::Parse {
            name: "sample",
            text: path.display().to_string(),
            reason,
        };
        let text = read_text(path, MAX_CONFIG_BYTES, refuse)?;
        Self::from_toml_in(&text, base, path.parent()).map_err(|e| match e {
            // The file's own faults name the file; a value's name the value, then the file.
            Error::Parse { name, text, reason } if text.is_empty() => Error::Parse {
                name,
                text: path.display().to_string(),
                reason,
            },
            Error::Parse { name, text, reason } => Error::Parse {
                name,
                text,
                reason: format!("{reason} (in {})", path.display()),
            },
            other => other,
        })
    }

    /// Parse a sample description, each material over `base` (it cannot name a mask
    /// file: [`Sample::from_file`]).
    pub fn from_toml(text: &str, base: &TapInputs) -> Result<Self> {
        Self::from_toml_in(text, base, None)
    }

    /// Parse a sample description, each material over `base`, a mask read from `dir`.
    fn from_toml_in(text: &str, base: &TapInputs, dir: Option<&Path>) -> Result<Self> {
        let bad = |reason: String| Error::Parse {
            name: "sample",
            text: String::new(),
            reason,
        };
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            bad(format!("not valid TOML: {}", e.to_string().trim_end()))
        })?;
        for key in table.keys() {
            if ![
                "length",
                "width",
                "material",
                "region",
                "mask",
                "mask-colours",
                "disc",
            ]
            .contains(&key.as_str())
            {
                return Err(bad(format!(
                    "unknown key {key}; a sample has length, width, [[material]], \
                     [[region]], mask, [mask-colours] and [[disc]]"
                )));
            }
        }
        let length_m = match table.get("length") {
            Some(v) => crate::app::config::length(&value_text(v, "length")?).map_err(bad)?,
            None => return Err(bad("the line's length is missing (length = \"1um\")".into())),
        };
        let width_m = match table.get("width") {
            Some(v) => crate::app::config::length(&value_text(v, "width")?).map_err(bad)?,
            None => length_m,
        };
        for (what, size) in [("length", length_m), ("width", width_m)] {
            if !(MIN_SIZE_M..=MAX_SIZE_M).contains(&size) {
                return Err(bad(format!(
                    "the sample's {what} ({size:e} m) lies outside what an AFM scans: \
                     {MIN_SIZE_M:e} to {MAX_SIZE_M:e} m"
                )));
            }
        }
        let list = |key: &str| -> Result<Vec<toml::Table>> {
            match table.get(key) {
                None if key == "disc" => Ok(Vec::new()),
                Some(toml::Value::Array(items)) if items.is_empty() && key != "disc" => {
                    Err(bad(format!("no [[{key}]] given (the list is empty)")))
                }
                Some(toml::Value::Array(items)) => items
                    .iter()
                    .map(|v| match v {
                        toml::Value::Table(t) => Ok(t.clone()),
                        _ => Err(bad(format!("each {key} is a table ([[{key}]])"))),
                    })
                    .collect(),
                Some(_) => Err(bad(format!("{key} is a list of tables ([[{key}]])"))),
                None => Err(bad(format!("no [[{key}]] given"))),
            }
        };
        let mut materials: Vec<(String, TapSetup)> = Vec::new();
        for m in list("material")? {
            let Some(toml::Value::String(name)) = m.get("name") else {
                return Err(bad("every [[material]] has a name (name = \"A\")".into()));
            };
            if materials.iter().any(|(n, _)| n == name) {
                return Err(bad(format!("material {name} is given twice")));
            }
            let mut inputs = TapInputs::default();
            for (key, value) in m.iter().filter(|(k, _)| *k != "name") {
                if ["separation", "setpoint", "amplitude-setpoint", "branch"]
                    .contains(&key.as_str())
                {
                    return Err(bad(format!(
                        "material {name}: {key} is the instrument's, not a material's"
                    )));
                }
                inputs.set(key, &value_text(value, key)?)?;
            }
            let (setup, _) = inputs.or(base.clone()).resolve()?;
            setup.check_plausible()?;
            if let Some((first, s)) = materials.first()
                && s.cantilever != setup.cantilever
            {
                return Err(bad(format!(
                    "materials {first} and {name} differ in the cantilever: one tip scans them all"
                )));
            }
            materials.push((name.clone(), setup));
        }
        if materials.len() > MAX_MATERIALS {
            return Err(bad(format!("more than {MAX_MATERIALS} materials")));
        }
        let mut regions: Vec<Region> = Vec::new();
        for r in list("region")? {
            for key in r.keys() {
                if !["until", "material", "height"].contains(&key.as_str()) {
                    return Err(bad(format!(
                        "unknown key {key} in a region (until, material, height)"
                    )));
                }
            }
            let until_m = match r.get("until") {
                Some(v) => crate::app::config::length(&value_text(v, "until")?).map_err(bad)?,
                None => return Err(bad("every [[region]] says where it ends (until)".into())),
            };
            let material =
                material_index(&materials, r.get("material"), "[[region]]").map_err(bad)?;
            let height_m = match r.get("height") {
                Some(v) => crate::app::config::length(&value_text(v, "height")?).map_err(bad)?,
                None => 0.0,
            };
            let start = regions.last().map_or(0.0, |r| r.until_m);
            if !(until_m > start && until_m <= length_m * (1.0 + 1e-12)) {
                return Err(bad(format!(
                    "region ends ({until_m:e} m) must rise from {start:e} m and stay within \
                     the line ({length_m:e} m)"
                )));
            }
            check_height(height_m).map_err(bad)?;
            regions.push(Region {
                until_m,
                material,
                height_m,
            });
            if regions.len() > MAX_REGIONS {
                return Err(bad(format!("more than {MAX_REGIONS} regions")));
            }
        }
        let end = regions.last().expect("a list is never empty").until_m;
        if end < length_m * (1.0 - 1e-12) {
            return Err(bad(format!(
                "the regions end at {end:e} m, short of the line ({length_m:e} m)"
            )));
        }
        let colours = match table.get("mask-colours") {
            None => None,
            Some(toml::Value::Table(t)) => Some(t),
            Some(_) => {
                return Err(bad(
                    "mask-colours is a table of colours ([mask-colours] \"#ff0000\" = \"B\")"
                        .into(),
                ));
            }
        };
        let mask = match table.get("mask") {
            None if colours.is_some() => {
                return Err(bad(
                    "[mask-colours] names the colours of a mask image, but no \
                     mask = \"mask.png\" is given"
                        .into(),
                ));
            }
            None => None,
            Some(toml::Value::String(file)) => {
                let Some(dir) = dir else {
                    return Err(bad("a mask is read from beside a sample file".into()));
                };
                let path = dir.join(file);
                let size_m = (length_m, width_m);
                let is_png = path
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("png"));
                Some(match (is_png, colours) {
                    (true, Some(colours)) => read_png_mask(&path, colours, &materials, size_m)?,
                    (true, None) => {
                        return Err(bad(format!(
                            "the mask image {file} needs its colours named: [mask-colours] \
                             \"#ff0000\" = \"B\" (or \"B@1nm\"), one line per colour"
                        )));
                    }
                    (false, None) => read_mask(&path, &materials, size_m)?,
                    (false, Some(_)) => {
                        return Err(bad(format!(
                            "[mask-colours] is for a mask image (.png); {file} is read as CSV \
                             of material names"
                        )));
                    }
                })
            }
            Some(_) => {
                return Err(bad(
                    "mask names a CSV or PNG file (mask = \"mask.csv\")".into()
                ));
            }
        };
        let mut discs = Vec::new();
        for d in list("disc")? {
            for key in d.keys() {
                if !["x", "y", "radius", "material", "height"].contains(&key.as_str()) {
                    return Err(bad(format!(
                        "unknown key {key} in a disc (x, y, radius, material, height)"
                    )));
                }
            }
            let at = |key: &str| -> Result<f64> {
                match d.get(key) {
                    Some(v) => crate::app::config::length(&value_text(v, key)?).map_err(bad),
                    None => Err(bad(format!("every [[disc]] gives its {key}"))),
                }
            };
            let (x, y, radius_m) = (at("x")?, at("y")?, at("radius")?);
            if !(x.is_finite() && y.is_finite() && radius_m > 0.0 && radius_m.is_finite()) {
                return Err(bad(format!(
                    "a disc's centre ({x:e}, {y:e}) m is finite and its radius ({radius_m:e} m) \
                     positive"
                )));
            }
            let height_m = match d.get("height") {
                Some(_) => at("height")?,
                None => 0.0,
            };
            check_height(height_m).map_err(bad)?;
            discs.push(Disc {
                centre_m: (x, y),
                radius_m,
                material: material_index(&materials, d.get("material"), "[[disc]]").map_err(bad)?,
                height_m,
            });
            if discs.len() > MAX_DISCS {
                return Err(bad(format!("more than {MAX_DISCS} discs")));
            }
        }
        Ok(Self {
            length_m,
            width_m,
            materials,
            layout: Layout {
                stripes: regions,
                mask,
                discs,
            },
        })
    }
}

/// The index of the material a region or disc names (`what`: which of them).
fn material_index(
    materials: &[(String, TapSetup)],
    name: Option<&toml::Value>,
    what: &str,
) -> std::result::Result<usize, String> {
    let Some(toml::Value::String(name)) = name else {
        return Err(format!(
            "every {what} names its material (material = \"A\")"
        ));
    };
    materials
        .iter()
        .position(|(n, _)| n == name)
        .ok_or_else(|| format!("{what} names material {name}, which is not given"))
}

/// A surface height is finite and at most 1 µm either way.
fn check_height(height_m: f64) -> std::result::Result<(), String> {
    if height_m.is_nan() || height_m.abs() > 1e-6 {
        return Err(format!(
            "a surface height ({height_m:e} m) is at most 1 µm either way"
        ));
    }
    Ok(())
}

/// The most cells of a mask.
pub const MAX_MASK_CELLS: usize = 1 << 20;

/// Read a mask CSV ([`Mask`]): rows of material names (`B`, or `B@1nm` with a surface
/// height; empty: what lies beneath), the first row the top of the image, every row as
/// long as the first, covering `size_m` (length, width).
fn read_mask(path: &Path, materials: &[(String, TapSetup)], size_m: (f64, f64)) -> Result<Mask> {
    let refuse = |reason: String| Error::Parse {
        name: "sample mask",
        text: path.display().to_string(),
        reason,
    };
    let text = read_text(path, MAX_CONFIG_BYTES, refuse)?;
    let mut cells: Vec<Vec<MaskCell>> = Vec::new();
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    for (r, record) in reader.records().enumerate() {
        let record = record.map_err(|e| refuse(format!("not CSV: {e}")))?;
        let row = record
            .iter()
            .enumerate()
            .map(|(c, cell)| {
                mask_cell(materials, cell)
                    .map_err(|e| refuse(format!("row {}, column {}: {e}", r + 1, c + 1)))
            })
            .collect::<Result<Vec<_>>>()?;
        if let Some(first) = cells.first()
            && first.len() != row.len()
        {
            return Err(refuse(format!(
                "row {} has {} cells, the first {}",
                r + 1,
                row.len(),
                first.len()
            )));
        }
        cells.push(row);
        if cells.len() * cells[0].len() > MAX_MASK_CELLS {
            return Err(refuse(format!("more than {MAX_MASK_CELLS} cells")));
        }
    }
    if cells.is_empty() || cells[0].is_empty() {
        return Err(refuse("no cells".into()));
    }
    Ok(Mask {
        columns: cells[0].len(),
        cells,
        size_m,
    })
}

/// A mask cell: its material and surface height in m, or nothing ([`Mask::cells`]).
type MaskCell = Option<(usize, f64)>;

/// A mask cell's text: `B`, `B@1nm` (material and surface height), or empty (nothing).
fn mask_cell(
    materials: &[(String, TapSetup)],
    cell: &str,
) -> std::result::Result<MaskCell, String> {
    let cell = cell.trim();
    if cell.is_empty() {
        return Ok(None);
    }
    let (name, height) = cell.split_once('@').unwrap_or((cell, "0"));
    let height_m = crate::app::config::length(height.trim())?;
    check_height(height_m)?;
    let value = toml::Value::String(name.trim().into());
    let material = material_index(materials, Some(&value), "mask cell")?;
    Ok(Some((material, height_m)))
}

/// The most bytes of a mask image read.
pub const MAX_MASK_PNG_BYTES: u64 = 16 << 20;

/// Read a mask image ([`Mask`]): a PNG, one cell a pixel, the top row the top of the
/// image; each opaque pixel's colour named in `colours` (`"#rrggbb" = "B"` or `"B@1nm"`),
/// a transparent pixel nothing. Its size is checked before it is decoded.
fn read_png_mask(
    path: &Path,
    colours: &toml::Table,
    materials: &[(String, TapSetup)],
    size_m: (f64, f64),
) -> Result<Mask> {
    let refuse = |reason: String| Error::Parse {
        name: "sample mask image",
        text: path.display().to_string(),
        reason,
    };
    let mut named: Vec<([u8; 3], MaskCell)> = Vec::new();
    for (key, value) in colours {
        let rgb = parse_colour(key).map_err(|e| refuse(format!("[mask-colours]: {e}")))?;
        let toml::Value::String(cell) = value else {
            return Err(refuse(format!(
                "[mask-colours] \"{key}\" names a material as text (\"B\" or \"B@1nm\")"
            )));
        };
        let cell = mask_cell(materials, cell)
            .map_err(|e| refuse(format!("[mask-colours] \"{key}\": {e}")))?
            .ok_or_else(|| {
                refuse(format!(
                    "[mask-colours] \"{key}\" is empty (a transparent pixel shows what lies \
                     beneath)"
                ))
            })?;
        if named.iter().any(|(c, _)| *c == rgb) {
            return Err(refuse(format!("[mask-colours] names {key} twice")));
        }
        named.push((rgb, Some(cell)));
    }
    let bytes = read_input(path, MAX_MASK_PNG_BYTES, refuse)?;
    let mut reader =
        image::io::Reader::with_format(std::io::Cursor::new(&bytes), image::ImageFormat::Png);
    let mut limits = image::io::Limits::default();
    limits.max_image_width = Some(MAX_MASK_SIDE);
    limits.max_image_height = Some(MAX_MASK_SIDE);
    limits.max_alloc = Some(16 * MAX_MASK_CELLS as u64);
    reader.limits(limits);
    let decoded = reader.decode().map_err(|e| {
        refuse(format!(
            "not a PNG image within {MAX_MASK_SIDE} pixels a side: {e}"
        ))
    })?;
    let (columns, rows) = (decoded.width() as usize, decoded.height() as usize);
    if columns * rows > MAX_MASK_CELLS {
        return Err(refuse(format!("more than {MAX_MASK_CELLS} pixels")));
    }
    let rgba = decoded.into_rgba8();
    let mut cells = vec![vec![None; columns]; rows];
    for (c, r, pixel) in rgba.enumerate_pixels() {
        let [red, green, blue, alpha] = pixel.0;
        let at = |reason: String| {
            refuse(format!(
                "row {}, column {} (#{red:02x}{green:02x}{blue:02x}): {reason}",
                r + 1,
                c + 1
            ))
        };
        cells[r as usize][c as usize] = match alpha {
            0 => None,
            255 => {
                named
                    .iter()
                    .find(|(rgb, _)| *rgb == [red, green, blue])
                    .ok_or_else(|| at("a colour [mask-colours] does not name".into()))?
                    .1
            }
            _ => {
                return Err(at(format!(
                    "partly transparent (alpha {alpha}); a mask's pixels are opaque or \
                     transparent (an antialiased edge?)"
                )));
            }
        };
    }
    Ok(Mask {
        columns,
        cells,
        size_m,
    })
}

/// The most pixels a side of a mask image.
pub const MAX_MASK_SIDE: u32 = 4096;

/// A colour `#rrggbb`.
fn parse_colour(text: &str) -> std::result::Result<[u8; 3], String> {
    let hex = text
        .strip_prefix('#')
        .filter(|h| h.len() == 6 && h.bytes().all(|b| b.is_ascii_hexdigit()))
        .ok_or_else(|| format!("{text} is not a colour #rrggbb"))?;
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).expect("checked hex digits");
    Ok([byte(0), byte(2), byte(4)])
}
