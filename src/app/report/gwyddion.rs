//! Images in Gwyddion's formats, written by tapsim itself from Gwyddion's published
//! descriptions (user guide, "Simple Field Files" and "Format of Gwyddion Files"):
//!
//! - **GSF** (Gwyddion Simple Field, one channel a file): the line `Gwyddion Simple
//!   Field 1.0`, `name = value` header lines (XRes, YRes, XReal, YReal, XOffset,
//!   YOffset, XYUnits, ZUnits, Title and any others), one to four NUL bytes aligning
//!   the data to a multiple of 4, then XRes·YRes little-endian float32 values, row by
//!   row, the first row the top of the image.
//! - **GWY** (native, every channel in one file): the magic `GWYP`, then a serialized
//!   `GwyContainer`. An object is its type name (NUL-terminated), the size of its
//!   components in bytes (u32) and the components, each a name (NUL-terminated), a type
//!   character and the value (`i` i32, `d` f64, `s` NUL-terminated string, `o` an
//!   object, `D` a u32 count and that many f64), all little-endian. Channel k is the
//!   container's `/k/data` (a `GwyDataField`: xres, yres, xreal, yreal, xoff, yoff, the
//!   units as `GwySIUnit` objects of one `unitstr`, and `data`) with its title at
//!   `/k/data/title`, and `/k/meta` a container of strings: the run's parameters.

/// One channel of an image.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Its title, as Gwyddion lists it ("Topography (trace)").
    pub title: String,
    /// The unit of its values ("m", "N", "J", "deg", "" for a ratio).
    pub unit: String,
    /// Pixels along x (a line).
    pub xres: usize,
    /// Rows (lines).
    pub yres: usize,
    /// The image's extent along x and y, m.
    pub size_m: (f64, f64),
    /// The values, row by row, the first row the top of the image (NaN: no value, which
    /// the formats cannot hold: written as 0 and listed in the metadata).
    pub values: Vec<f64>,
}

impl Channel {
    /// The values with a missing one as 0, and how many were missing.
    fn finite(&self) -> (Vec<f64>, usize) {
        let missing = self.values.iter().filter(|v| !v.is_finite()).count();
        let values = self
            .values
            .iter()
            .map(|&v| if v.is_finite() { v } else { 0.0 })
            .collect();
        (values, missing)
    }
}

/// The GSF file of `channel`, with `meta` as extra header lines.
pub fn gsf(channel: &Channel, meta: &[(String, String)]) -> Vec<u8> {
    let (values, missing) = channel.finite();
    let mut head = String::from("Gwyddion Simple Field 1.0\n");
    let mut line = |k: &str, v: &str| head.push_str(&format!("{k} = {v}\n"));
    line("XRes", &channel.xres.to_string());
    line("YRes", &channel.yres.to_string());
    line("XReal", &format!("{:e}", channel.size_m.0));
    line("YReal", &format!("{:e}", channel.size_m.1));
    line("XOffset", "0");
    line("YOffset", "0");
    line("XYUnits", "m");
    line("ZUnits", &channel.unit);
    line("Title", &channel.title);
    if missing > 0 {
        line("MissingValues", &format!("{missing} written as 0"));
    }
    for (k, v) in meta {
        // Header names are identifiers; values one line.
        let key: String = k
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        line(&key, &v.replace('\n', " "));
    }
    let mut out = head.into_bytes();
    let pad = 4 - out.len() % 4;
    out.extend(std::iter::repeat_n(0u8, pad));
    for v in values {
        out.extend((v as f32).to_le_bytes());
    }
    out
}

/// A serialized GWY object under construction: its components.
struct Object {
    name: &'static str,
    body: Vec<u8>,
}

impl Object {
    fn new(name: &'static str) -> Self {
        Self {
            name,
            body: Vec::new(),
        }
    }

    fn key(&mut self, key: &str, kind: u8) {
        self.body.extend(key.as_bytes());
        self.body.push(0);
        self.body.push(kind);
    }

    fn int(mut self, key: &str, v: i32) -> Self {
        self.key(key, b'i');
        self.body.extend(v.to_le_bytes());
        self
    }

    fn double(mut self, key: &str, v: f64) -> Self {
        self.key(key, b'd');
        self.body.extend(v.to_le_bytes());
        self
    }

    fn string(mut self, key: &str, v: &str) -> Self {
        self.key(key, b's');
        // (A NUL inside would end the string early.)
        self.body.extend(v.replace('\0', " ").as_bytes());
        self.body.push(0);
        self
    }

    fn object(mut self, key: &str, v: Object) -> Self {
        self.key(key, b'o');
        self.body.extend(v.bytes());
        self
    }

    fn doubles(mut self, key: &str, v: &[f64]) -> Self {
        self.key(key, b'D');
        self.body
            .extend(u32::try_from(v.len()).unwrap_or(u32::MAX).to_le_bytes());
        for x in v {
            self.body.extend(x.to_le_bytes());
        }
        self
    }

    fn bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.name.len() + 5 + self.body.len());
        out.extend(self.name.as_bytes());
        out.push(0);
        out.extend(
            u32::try_from(self.body.len())
                .unwrap_or(u32::MAX)
                .to_le_bytes(),
        );
        out.extend(&self.body);
        out
    }
}

/// A `GwySIUnit` of `unit`.
fn unit(unit: &str) -> Object {
    Object::new("GwySIUnit").string("unitstr", unit)
}

/// The GWY file holding `channels` (each with `meta`, the run's parameters, as its
/// metadata).
pub fn gwy(channels: &[Channel], meta: &[(String, String)]) -> Vec<u8> {
    let mut container = Object::new("GwyContainer");
    for (k, channel) in channels.iter().enumerate() {
        let (values, missing) = channel.finite();
        let field = Object::new("GwyDataField")
            .int("xres", i32::try_from(channel.xres).unwrap_or(i32::MAX))
            .int("yres", i32::try_from(channel.yres).unwrap_or(i32::MAX))
            .double("xreal", channel.size_m.0)
            .double("yreal", channel.size_m.1)
            .double("xoff", 0.0)
            .double("yoff", 0.0)
            .object("si_unit_xy", unit("m"))
            .object("si_unit_z", unit(&channel.unit))
            .doubles("data", &values);
        let mut info = Object::new("GwyContainer");
        for (key, value) in meta {
            info = info.string(key, value);
        }
        if missing > 0 {
            info = info.string("Missing values", &format!("{missing} written as 0"));
        }
        container = container
            .object(&format!("/{k}/data"), field)
            .string(&format!("/{k}/data/title"), &channel.title)
            .object(&format!("/{k}/meta"), info);
    }
    let mut out = b"GWYP".to_vec();
    out.extend(container.bytes());
    out
}

/// `values` (row by row, `xres` a row) less their least-squares plane a + bx + cy over
/// the pixel indices: a levelled topography, as Gwyddion's "plane level" gives it
/// (non-finite values left out of the fit and kept as they are).
pub fn plane_levelled(values: &[f64], xres: usize) -> Vec<f64> {
    let xres = xres.max(1);
    let points: Vec<(f64, f64, f64)> = values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .map(|(i, &v)| ((i % xres) as f64, (i / xres) as f64, v))
        .collect();
    let n = points.len() as f64;
    if points.is_empty() {
        return values.to_vec();
    }
    let mean = |f: &dyn Fn(&(f64, f64, f64)) -> f64| points.iter().map(f).sum::<f64>() / n;
    let (mx, my, mz) = (mean(&|p| p.0), mean(&|p| p.1), mean(&|p| p.2));
    let s = |f: &dyn Fn(&(f64, f64, f64)) -> f64| points.iter().map(f).sum::<f64>();
    let (sxx, syy, sxy) = (
        s(&|p| (p.0 - mx) * (p.0 - mx)),
        s(&|p| (p.1 - my) * (p.1 - my)),
        s(&|p| (p.0 - mx) * (p.1 - my)),
    );
    let (sxz, syz) = (
        s(&|p| (p.0 - mx) * (p.2 - mz)),
        s(&|p| (p.1 - my) * (p.2 - mz)),
    );
    let det = sxx * syy - sxy * sxy;
    let (b, c) = if det.abs() > 0.0 {
        ((sxz * syy - syz * sxy) / det, (syz * sxx - sxz * sxy) / det)
    } else if sxx > 0.0 {
        (sxz / sxx, 0.0)
    } else if syy > 0.0 {
        (0.0, syz / syy)
    } else {
        (0.0, 0.0)
    };
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let (x, y) = ((i % xres) as f64, (i / xres) as f64);
            v - (mz + b * (x - mx) + c * (y - my))
        })
        .collect()
}
