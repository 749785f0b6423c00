//! One source feature as the per-feature path sees it: owned data, no GDAL.
//!
//! The reader (`io::reader`, with the `gdal` feature) makes these from any OGR source; the
//! per-feature work ([`crate::process`]) turns each into its output rows
//! ([`crate::output`]) without touching a file.

/// An attribute value of a source feature, carried unchanged to the output.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// NULL.
    Null,
    /// 32-bit integer.
    Integer(i32),
    /// 64-bit integer.
    Integer64(i64),
    /// Floating point.
    Real(f64),
    /// Text.
    Text(String),
    /// Date.
    Date(chrono::NaiveDate),
    /// Date and time with its offset.
    DateTime(chrono::DateTime<chrono::FixedOffset>),
    /// List of 32-bit integers.
    IntegerList(Vec<i32>),
    /// List of 64-bit integers.
    Integer64List(Vec<i64>),
    /// List of floating point numbers.
    RealList(Vec<f64>),
    /// List of texts.
    TextList(Vec<String>),
}

impl Value {
    /// The value as text (joins by key, logs and tests); `None` for NULL.
    pub fn as_text(&self) -> Option<String> {
        Some(match self {
            Value::Null => return None,
            Value::Integer(i) => i.to_string(),
            Value::Integer64(i) => i.to_string(),
            Value::Real(r) => r.to_string(),
            Value::Text(s) => s.clone(),
            other => format!("{other:?}"),
        })
    }
}

/// One source feature, owned.
#[derive(Debug, Clone, PartialEq)]
pub struct Feature {
    /// The source FID.
    pub fid: Option<u64>,
    /// Attribute values in the source's field order.
    pub attributes: Vec<Value>,
    /// The geometry (2D, linear, reprojected); `None` when NULL or unreadable.
    pub geometry: Option<geo::Geometry<f64>>,
    /// Why the geometry could not be read, when it could not.
    pub geometry_error: Option<String>,
    /// The source geometry as WKB (2D), kept for the `rejected` layer.
    pub source_wkb: Option<Vec<u8>>,
    /// Set when MakeValid changed the geometry.
    pub repaired: bool,
    /// Set when the reader found the geometry valid by the check `prepare`
    /// makes (a polygon without holes, `make_valid` on), which then does not
    /// make it again.
    pub checked: bool,
    /// The source FIDs dissolved into this feature by `input.merge_adjacent`
    /// (empty: the feature is only itself).
    pub members: Vec<u64>,
    /// The source geometries of `members`, in the same order, kept for
    /// the `rejected` layer (a rejected group lists every member).
    pub member_wkb: Vec<Option<Vec<u8>>>,
}

/// A source FID as messages name it: the number, or `(no fid)`.
pub fn fid_text(fid: Option<u64>) -> String {
    fid.map_or_else(|| "(no fid)".into(), |f| f.to_string())
}

impl Feature {
    /// How many source features this one stands for.
    pub fn source_count(&self) -> u64 {
        self.members.len().max(1) as u64
    }
}

impl Feature {
    /// A feature with only a geometry (library use, tests).
    pub fn from_geometry(fid: Option<u64>, geometry: geo::Geometry<f64>) -> Self {
        Self {
            geometry: Some(geometry),
            ..Self::new(fid, Vec::new())
        }
    }

    /// A feature with its FID and source fields, no geometry yet, standing
    /// for itself alone (not merged, not repaired, not checked).
    pub fn new(fid: Option<u64>, attributes: Vec<Value>) -> Self {
        Self {
            fid,
            attributes,
            geometry: None,
            geometry_error: None,
            source_wkb: None,
            repaired: false,
            checked: false,
            members: Vec::new(),
            member_wkb: Vec::new(),
        }
    }
}
