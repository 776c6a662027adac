//! `[fiducial]`: the visual target, named by its `kind`.
//!
//! A profile's `[fiducial]` table says which kind of fiducial the dock carries and, in
//! the same table, that kind's own fields:
//!
//! ```toml
//! [fiducial]
//! kind = "two_block"
//! width_m = 0.18
//! height_m = 0.11
//! left_color = "cyan"
//! right_color = "magenta"
//! center_height_m = 0.28
//! ```
//!
//! Each kind is a type implementing [`FiducialKind`], registered by name in a
//! [`FiducialKinds`]: the crate's four ([`TwoBlockSpec`], [`PyramidSpec`], [`CirclesSpec`],
//! [`MarkersSpec`]) are in [`FiducialKinds::builtin`], and a user's crate registers its own
//! beside them ([`FiducialKinds::register`]), so the generic profile names none of them.
//! Loading parses the table into the kind's type once (strictly: an unknown field is an
//! error naming its line) and runs its checks; code that needs the fiducial asks for its
//! type with [`FiducialSpec::get`].

use crate::config::Validator;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

/// A named colour for fiducials and the segmentation's table defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NamedColor {
    /// (0, 255, 255).
    Cyan,
    /// (255, 0, 255).
    Magenta,
    /// (255, 255, 0).
    Yellow,
    /// (255, 128, 0).
    Orange,
    /// (0, 64, 255).
    Blue,
    /// (255, 0, 0).
    Red,
    /// (0, 200, 0).
    Green,
    /// (255, 255, 255).
    White,
    /// (0, 0, 0).
    Black,
}

impl NamedColor {
    /// The name used in TOML and output (`"cyan"`).
    pub fn as_str(&self) -> &'static str {
        match self {
            NamedColor::Cyan => "cyan",
            NamedColor::Magenta => "magenta",
            NamedColor::Yellow => "yellow",
            NamedColor::Orange => "orange",
            NamedColor::Blue => "blue",
            NamedColor::Red => "red",
            NamedColor::Green => "green",
            NamedColor::White => "white",
            NamedColor::Black => "black",
        }
    }

    /// Nominal sRGB value of the paint's pigment. A real paint is paler: see
    /// [`NamedColor::reflectance`] and [`NamedColor::paint_srgb`] (`profile::paint`).
    pub fn rgb(&self) -> [u8; 3] {
        match self {
            NamedColor::Cyan => [0, 255, 255],
            NamedColor::Magenta => [255, 0, 255],
            NamedColor::Yellow => [255, 255, 0],
            NamedColor::Orange => [255, 128, 0],
            NamedColor::Blue => [0, 64, 255],
            NamedColor::Red => [255, 0, 0],
            NamedColor::Green => [0, 200, 0],
            NamedColor::White => [255, 255, 255],
            NamedColor::Black => [0, 0, 0],
        }
    }
}

/// Bujold's two-block flap (seed 004 §V).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoBlockSpec {
    /// Overall width of the flap, m.
    pub width_m: f64,
    /// Height of the flap, m.
    pub height_m: f64,
    /// Colour of the block on the left when facing the fiducial from outside the dock.
    pub left_color: NamedColor,
    /// Colour of the block on the right when facing the fiducial.
    pub right_color: NamedColor,
    /// Height of the flap's centre above the ground, m.
    pub center_height_m: f64,
}

/// RAPOSA's tether-end pyramid: an orange ball/guide and blue edges (seed 001 §II.C).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PyramidSpec {
    /// Diameter of the orange bi-conical guide, m.
    pub ball_diameter_m: f64,
    /// Length h of each painted blue edge, m.
    pub blue_edge_length_m: f64,
    /// Distance m from a blue edge's midpoint to the ellipse centre (top view), m.
    pub edge_to_ball_m: f64,
    /// Height of the ball's centre above the ground, m.
    pub ball_height_m: f64,
    /// Colour of the guide.
    pub ball_color: NamedColor,
    /// Colour of the edges.
    pub edge_color: NamedColor,
}

/// One of Axel's circular fiducials on the central module.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CirclePlacement {
    /// Position across the module face (dock frame y), m.
    pub y_m: f64,
    /// Height above the ground, m.
    pub z_m: f64,
    /// Pattern rotation: one of −45, 0, 45, 90 degrees.
    pub rotation_deg: f64,
}

/// Axel's eight circular fiducials (seed 000).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CirclesSpec {
    /// Outer diameter of every circle, m.
    pub diameter_m: f64,
    /// Placements in an asymmetric layout.
    pub placements: Vec<CirclePlacement>,
    /// The paper's fixed thresholds in place of our adaptive one, `[black_below,
    /// white_above]` grey levels (0–255, grey = (R + 2G + B)/4): darker pixels are black,
    /// brighter ones white, everywhere in the frame. Seed 000 §V-E docked 8 of 15 runs
    /// with fixed thresholds under an uneven shadow and gives no levels. For comparison
    /// only; absent (the default), the detector thresholds against the local mean.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixed_threshold: Option<[u8; 2]>,
}

/// The AutoKrawler's magenta body markers (seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkersSpec {
    /// Number of markers.
    pub count: usize,
    /// Side of each square marker, m.
    pub side_m: f64,
    /// Marker colour.
    pub color: NamedColor,
    /// Steering calibration λ = f(x) per axle (front, rear), for the tie-rod ratio x
    /// (seed 003 eq. 5, Fig. 6): the coefficients of 1, (x − 1), (x − 1)² and optionally
    /// (x − 1)³, degrees. Fitted and written by `marsupial calibrate-steering`; without
    /// it the steering is not estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering_poly_deg: Option<[SteeringCoeffs; 2]>,
}

/// One axle's steering polynomial as a profile writes it: three coefficients (the
/// paper's second order) or four (third order), degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<f64>", into = "Vec<f64>")]
pub struct SteeringCoeffs {
    /// Coefficients of 1, (x − 1), (x − 1)², (x − 1)³ (0 for a second-order polynomial).
    pub deg: [f64; 4],
    /// 2 or 3.
    pub order: usize,
}

impl TryFrom<Vec<f64>> for SteeringCoeffs {
    type Error = String;

    fn try_from(v: Vec<f64>) -> Result<Self, String> {
        match v[..] {
            [a, b, c] => Ok(Self {
                deg: [a, b, c, 0.0],
                order: 2,
            }),
            [a, b, c, d] => Ok(Self {
                deg: [a, b, c, d],
                order: 3,
            }),
            _ => Err(format!(
                "expected 3 coefficients (second order) or 4 (third order), got {}",
                v.len()
            )),
        }
    }
}

impl From<SteeringCoeffs> for Vec<f64> {
    fn from(c: SteeringCoeffs) -> Self {
        c.deg[..=c.order].to_vec()
    }
}

/// A kind of fiducial a profile's `[fiducial]` table can name (see the module docs).
///
/// The type is the table's schema: use `#[serde(deny_unknown_fields)]` so a misspelt
/// field is refused. Field paths in [`FiducialKind::validate`]'s problems start with
/// `fiducial.` (`fiducial.width_m`), so they name the profile's line.
pub trait FiducialKind: Serialize + DeserializeOwned + Clone + fmt::Debug + Send + Sync + 'static {
    /// The name `[fiducial] kind` gives (`"two_block"`).
    const KIND: &'static str;

    /// Range and consistency checks beyond what the type's fields say (none by default).
    fn validate(&self, v: &mut Validator<'_>) {
        let _ = v;
    }
}

impl FiducialKind for TwoBlockSpec {
    const KIND: &'static str = "two_block";

    fn validate(&self, v: &mut Validator<'_>) {
        v.positive("fiducial.width_m", self.width_m);
        v.positive("fiducial.height_m", self.height_m);
        v.non_negative("fiducial.center_height_m", self.center_height_m);
        v.require(self.left_color != self.right_color, "fiducial.right_color", || {
            "expected the two blocks to have different colours".into()
        });
    }
}

impl FiducialKind for PyramidSpec {
    const KIND: &'static str = "pyramid";

    fn validate(&self, v: &mut Validator<'_>) {
        v.positive("fiducial.ball_diameter_m", self.ball_diameter_m);
        v.positive("fiducial.blue_edge_length_m", self.blue_edge_length_m);
        v.positive("fiducial.edge_to_ball_m", self.edge_to_ball_m);
        v.non_negative("fiducial.ball_height_m", self.ball_height_m);
    }
}

impl FiducialKind for CirclesSpec {
    const KIND: &'static str = "circles";

    fn validate(&self, v: &mut Validator<'_>) {
        v.positive("fiducial.diameter_m", self.diameter_m);
        v.require(self.placements.len() >= 5, "fiducial.placements", || {
            format!(
                "expected at least 5 circles (4 make the homography degenerate), got {}",
                self.placements.len()
            )
        });
        for (i, pl) in self.placements.iter().enumerate() {
            v.finite(&format!("fiducial.placements[{i}].y_m"), pl.y_m);
            v.non_negative(&format!("fiducial.placements[{i}].z_m"), pl.z_m);
            v.require(
                [-45.0, 0.0, 45.0, 90.0].contains(&pl.rotation_deg),
                &format!("fiducial.placements[{i}].rotation_deg"),
                || format!("expected one of −45, 0, 45, 90, got {}", pl.rotation_deg),
            );
        }
        if let Some([black, white]) = self.fixed_threshold {
            v.require(black <= white, "fiducial.fixed_threshold", || {
                format!("expected [black_below, white_above] with black_below ≤ white_above, got [{black}, {white}]")
            });
        }
    }
}

impl FiducialKind for MarkersSpec {
    const KIND: &'static str = "markers";

    fn validate(&self, v: &mut Validator<'_>) {
        v.nonzero("fiducial.count", self.count);
        v.positive("fiducial.side_m", self.side_m);
        for (a, poly) in self.steering_poly_deg.iter().flatten().enumerate() {
            for (k, c) in poly.deg[..=poly.order].iter().enumerate() {
                v.finite(&format!("fiducial.steering_poly_deg[{a}][{k}]"), *c);
            }
        }
    }
}

/// A parsed fiducial value, type-erased.
type Value = Arc<dyn Any + Send + Sync>;

/// Parses one kind's table: the value, or the field path (below `fiducial.`) and message.
type ParseFn = dyn Fn(&toml::Table) -> Result<Value, (String, String)> + Send + Sync;

/// Checks one kind's parsed value.
type CheckFn = dyn Fn(&dyn Any, &mut Validator<'_>) + Send + Sync;

/// Deserializes `table` into `T` strictly, with the path of the field at fault.
///
/// # Errors
/// The path of the offending field (empty for the table itself) and the message.
pub fn parse_table<T: DeserializeOwned>(table: &toml::Table) -> Result<T, (String, String)> {
    let de = toml::Value::Table(table.clone());
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let path = if path == "." { String::new() } else { path };
        (path, e.into_inner().message().trim().to_string())
    })
}

/// Takes the `kind` string out of a kind-tagged table (`[fiducial]`, `[robot]`); `what`
/// says what it names, for the error.
pub(crate) fn take_kind<E: serde::de::Error>(table: &mut toml::Table, what: &str) -> Result<String, E> {
    match table.remove("kind") {
        Some(toml::Value::String(k)) => Ok(k),
        Some(other) => Err(E::custom(format!(
            "expected `kind` to be a string naming {what}, got {}",
            other.type_str()
        ))),
        None => Err(E::custom(format!("missing field `kind`: {what}"))),
    }
}

/// The fiducial kinds a profile may name, by name (see the module docs).
#[derive(Clone)]
pub struct FiducialKinds {
    kinds: BTreeMap<&'static str, (Arc<ParseFn>, Arc<CheckFn>)>,
}

impl fmt::Debug for FiducialKinds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.kinds.keys()).finish()
    }
}

impl Default for FiducialKinds {
    fn default() -> Self {
        Self::builtin()
    }
}

impl FiducialKinds {
    /// No kinds at all.
    pub fn empty() -> Self {
        Self { kinds: BTreeMap::new() }
    }

    /// The crate's kinds: `two_block`, `pyramid`, `circles` and `markers`.
    pub fn builtin() -> Self {
        let mut k = Self::empty();
        k.register::<TwoBlockSpec>()
            .register::<PyramidSpec>()
            .register::<CirclesSpec>()
            .register::<MarkersSpec>();
        k
    }

    /// Registers (or replaces) kind `F` under [`FiducialKind::KIND`].
    pub fn register<F: FiducialKind>(&mut self) -> &mut Self {
        let parse: Arc<ParseFn> = Arc::new(|t| parse_table::<F>(t).map(|f| Arc::new(f) as Value));
        let check: Arc<CheckFn> = Arc::new(|value, v| {
            if let Some(f) = value.downcast_ref::<F>() {
                f.validate(v);
            }
        });
        self.kinds.insert(F::KIND, (parse, check));
        self
    }

    /// The registered names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.kinds.keys().copied()
    }

    /// True when `kind` is registered.
    pub fn contains(&self, kind: &str) -> bool {
        self.kinds.contains_key(kind)
    }

    /// Parses `spec`'s table as its kind and checks it; problems go to `v`, at paths
    /// below `fiducial`.
    pub(crate) fn resolve(&self, spec: &mut FiducialSpec, v: &mut Validator<'_>) {
        let Some((parse, check)) = self.kinds.get(spec.kind.as_str()) else {
            let known: Vec<&str> = self.names().collect();
            v.problem(
                "fiducial.kind",
                format!(
                    "unknown fiducial kind `{}` (registered: {})",
                    spec.kind,
                    known.join(", ")
                ),
            );
            return;
        };
        match parse(&spec.params) {
            Ok(value) => {
                check(value.as_ref(), v);
                spec.value = Some(value);
            }
            Err((path, message)) => {
                let path = if path.is_empty() {
                    "fiducial".to_string()
                } else {
                    format!("fiducial.{path}")
                };
                v.problem(&path, message);
            }
        }
    }
}

/// The `[fiducial]` table: a registered kind and its fields (see the module docs).
#[derive(Clone, Default)]
pub struct FiducialSpec {
    kind: String,
    /// The table as written, less `kind`.
    params: toml::Table,
    /// The table parsed as its kind, once the profile has loaded.
    value: Option<Value>,
}

impl FiducialSpec {
    /// A fiducial of kind `F` (for profiles built in code).
    pub fn new<F: FiducialKind>(spec: F) -> Self {
        let mut s = Self::default();
        s.set(spec);
        s
    }

    /// The kind's name (`"two_block"`).
    pub fn kind(&self) -> &str {
        &self.kind
    }

    /// The kind's fields as written (less `kind`).
    pub fn params(&self) -> &toml::Table {
        &self.params
    }

    /// The fiducial as kind `F`; `None` when the profile's fiducial is another kind.
    pub fn get<F: FiducialKind>(&self) -> Option<&F> {
        if self.kind != F::KIND {
            return None;
        }
        self.value.as_ref()?.downcast_ref::<F>()
    }

    /// The fiducial as kind `F`, or a message saying what the profile has instead.
    ///
    /// # Errors
    /// A message naming the kind needed and the kind the profile declares.
    pub fn require<F: FiducialKind>(&self) -> Result<&F, String> {
        self.get::<F>().ok_or_else(|| {
            format!(
                "needs a fiducial of kind `{}`, and the profile's is `{}`",
                F::KIND,
                self.kind
            )
        })
    }

    /// Replaces the fiducial with `spec` (a scenario's repainted flap, a profile built in
    /// code).
    pub fn set<F: FiducialKind>(&mut self, spec: F) {
        self.kind = F::KIND.to_string();
        self.params = toml::Table::try_from(&spec).unwrap_or_default();
        self.value = Some(Arc::new(spec));
    }
}

impl PartialEq for FiducialSpec {
    fn eq(&self, other: &Self) -> bool {
        self.kind == other.kind && self.params == other.params
    }
}

impl fmt::Debug for FiducialSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("FiducialSpec")
            .field("kind", &self.kind)
            .field("params", &self.params)
            .finish()
    }
}

impl Serialize for FiducialSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = toml::Table::new();
        t.insert("kind".into(), toml::Value::String(self.kind.clone()));
        t.extend(self.params.clone());
        t.serialize(s)
    }
}

impl<'de> Deserialize<'de> for FiducialSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut params = toml::Table::deserialize(d)?;
        let kind = take_kind(
            &mut params,
            "the fiducial's kind (two_block, pyramid, circles, markers, or one a crate registers)",
        )?;
        Ok(Self {
            kind,
            params,
            value: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(src: &str) -> toml::Table {
        src.parse().unwrap()
    }

    #[test]
    fn a_builtin_kind_parses_and_is_found_by_its_type() {
        let mut spec: FiducialSpec = table(
            "kind = 'two_block'\nwidth_m = 0.18\nheight_m = 0.11\nleft_color = 'cyan'\nright_color = 'magenta'\ncenter_height_m = 0.28",
        )
        .try_into()
        .unwrap();
        let mut v = Validator::new("", None);
        FiducialKinds::builtin().resolve(&mut spec, &mut v);
        assert!(v.into_problems().is_empty());
        assert_eq!(spec.get::<TwoBlockSpec>().unwrap().width_m, 0.18);
        assert!(spec.get::<PyramidSpec>().is_none());
        assert!(spec.require::<CirclesSpec>().unwrap_err().contains("`circles`"));
    }

    #[test]
    fn an_unknown_kind_lists_the_registered_ones() {
        let mut spec: FiducialSpec = table("kind = 'beacon'").try_into().unwrap();
        let mut v = Validator::new("", None);
        FiducialKinds::builtin().resolve(&mut spec, &mut v);
        let p = v.into_problems();
        assert_eq!(p[0].path, "fiducial.kind");
        assert!(
            p[0].message.contains("circles, markers, pyramid, two_block"),
            "{}",
            p[0].message
        );
    }

    #[test]
    fn a_field_of_another_kind_is_refused_by_name() {
        let mut spec: FiducialSpec = table("kind = 'pyramid'\nwidth_m = 0.18").try_into().unwrap();
        let mut v = Validator::new("", None);
        FiducialKinds::builtin().resolve(&mut spec, &mut v);
        let p = v.into_problems();
        assert!(p[0].message.contains("width_m"), "{:?}", p);
    }

    #[test]
    fn set_round_trips_through_the_table() {
        let spec = TwoBlockSpec {
            width_m: 0.2,
            height_m: 0.1,
            left_color: NamedColor::Cyan,
            right_color: NamedColor::Yellow,
            center_height_m: 0.3,
        };
        let f = FiducialSpec::new(spec);
        assert_eq!(f.kind(), "two_block");
        assert_eq!(parse_table::<TwoBlockSpec>(f.params()).unwrap(), spec);
    }
}
