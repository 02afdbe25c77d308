//! Facades: a style fitted to one face of a building.

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use crate::axis::{AxisStyle, AxisSums};
use crate::error::{FacadeError, Result, check_range};
use crate::image::ImageSet;
use crate::interval::IntervalGroup;
use crate::profile::Profile;
use crate::sample::{FacadeSample, mix64, unit};
use crate::stack::LayerStack;
use crate::style::{BuildContext, StackStyle};
use crate::tile_plan::TileAnalysis;
use crate::tiles::TileOptions;
use crate::{MAX_FLOORS, MAX_LENGTH_M};

/// What a face is for; decides which layers and rows it gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum FaceRole {
    /// A street front: every layer, including entrances.
    #[default]
    Street,
    /// A side or rear wall: no street-only layers (no entrance).
    Side,
    /// A blind wall (party wall, firewall): no openings at all.
    Blank,
    /// Only the ground-floor rows (a podium face of its own).
    GroundFloor,
    /// Only the storeys above the ground floor (a tower face above a podium).
    UpperFloors,
}

/// One face to texture, as the buildings stage (or a user) describes it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct FacadeSpec {
    /// Width along the wall, metres (`s` runs left to right seen from outside).
    pub width_m: f64,
    /// Height, metres (`t` runs up from the face's bottom edge).
    pub height_m: f64,
    /// Storey count, if the building knows it; the style's rows are fitted to it when
    /// that fits the height. Default: `None` (best fit).
    #[cfg_attr(feature = "serde", serde(default))]
    pub floors: Option<u32>,
    /// What the face is for. Default: street.
    #[cfg_attr(feature = "serde", serde(default))]
    pub role: FaceRole,
    /// Seed of this facade (e.g. derived from the building id and face index).
    #[cfg_attr(feature = "serde", serde(default))]
    pub seed: u64,
}

impl FacadeSpec {
    /// A street face of the given size with a seed.
    pub fn new(width_m: f64, height_m: f64, seed: u64) -> Self {
        FacadeSpec {
            width_m,
            height_m,
            floors: None,
            role: FaceRole::Street,
            seed,
        }
    }

    /// Checks the numbers.
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`].
    pub fn validate(&self) -> Result<()> {
        check_range(
            "facade width_m",
            self.width_m,
            f64::MIN_POSITIVE,
            MAX_LENGTH_M,
            "(0, 100000] m",
        )?;
        check_range(
            "facade height_m",
            self.height_m,
            f64::MIN_POSITIVE,
            MAX_LENGTH_M,
            "(0, 100000] m",
        )?;
        if let Some(f) = self.floors {
            check_range(
                "floors",
                f64::from(f),
                0.0,
                f64::from(MAX_FLOORS),
                "[0, 10000]",
            )?;
        }
        Ok(())
    }
}

/// A facade style: the primary grid and the layer stack (serialisable).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct FacadeStyle {
    /// Name (also salts the facade seed).
    pub name: String,
    /// Columns of the primary grid (bays).
    pub columns: AxisStyle,
    /// Rows of the primary grid (plinth, ground floor, storeys, cornice).
    pub rows: AxisStyle,
    /// The layers over the grid.
    pub stack: StackStyle,
    /// How the shared tile set is cut. Default: see [`TileOptions`].
    #[cfg_attr(feature = "serde", serde(default))]
    pub tiles: TileOptions,
    /// Per-facade brightness variation (0.1 = ±10 %). Default: 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub tint_jitter: f32,
}

impl FacadeStyle {
    /// Checks the whole style.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] or [`FacadeError::UnknownLayer`] naming the fault.
    pub fn validate(&self) -> Result<()> {
        self.columns.validate(&format!("{}.columns", self.name))?;
        self.rows.validate(&format!("{}.rows", self.name))?;
        self.stack.validate(0)?;
        self.tiles.validate()?;
        if !(self.tint_jitter.is_finite() && (0.0..1.0).contains(&self.tint_jitter)) {
            return Err(FacadeError::InvalidStyle {
                style: self.name.clone(),
                reason: "tint_jitter must be in [0, 1)".into(),
            });
        }
        Ok(())
    }

    /// The style as pretty-printed JSON (a starting point for a style file). Feature
    /// `serde`.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] if the style holds closures (which cannot be
    /// serialised).
    #[cfg(feature = "serde")]
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| FacadeError::InvalidStyle {
            style: self.name.clone(),
            reason: format!("cannot serialise: {e}"),
        })
    }

    /// Reads and validates a style from JSON. Feature `serde`.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] with the parser's message (line and column) for
    /// malformed JSON, or the validation error.
    #[cfg(feature = "serde")]
    pub fn from_json(text: &str) -> Result<Self> {
        let style: FacadeStyle =
            serde_json::from_str(text).map_err(|e| FacadeError::InvalidStyle {
                style: "<json>".into(),
                reason: e.to_string(),
            })?;
        style.validate()?;
        Ok(style)
    }

    /// The smallest facade `[width, height]` (metres) the grid fits; smaller faces get a
    /// blank grid (see [`Facade::new`]).
    pub fn min_size(&self) -> [f64; 2] {
        [self.columns.min_length(), self.rows.min_length()]
    }
}

/// A validated style with its images drawn once: build many facades from it.
#[derive(Debug, Clone)]
pub struct PreparedStyle {
    style: FacadeStyle,
    images: BTreeMap<String, ImageSet>,
    salt: u64,
    /// What the style's tile set reproduces (computed on first use).
    tiling: OnceLock<Arc<TileAnalysis>>,
    /// The rows of a ground-floor face and of an upper-floors face (the other roles use
    /// the style's rows), derived once.
    rows_ground: AxisStyle,
    rows_upper: AxisStyle,
    /// The fitting sums of the columns and of the rows of each role (ground floor, upper
    /// floors, any other), computed once.
    columns_sums: AxisSums,
    rows_sums: [AxisSums; 3],
}

/// What had to be simplified while fitting a facade.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FacadeReport {
    /// The columns did not fit (face narrower than the style minimum): one blank column.
    pub blank_columns: bool,
    /// The rows did not fit: one blank row.
    pub blank_rows: bool,
    /// Layers left out because their own axes did not fit (name, reason).
    pub skipped_layers: Vec<(String, String)>,
    /// Storeys of the fitted rows.
    pub floors: usize,
}

/// The primary grid of a style fitted to one face (see [`PreparedStyle::layout`]).
#[derive(Debug, Clone)]
pub struct FacadeLayout {
    pub(crate) spec: FacadeSpec,
    pub(crate) columns: IntervalGroup,
    pub(crate) rows: IntervalGroup,
    pub(crate) report: FacadeReport,
}

impl FacadeLayout {
    /// The spec it was fitted to.
    pub fn spec(&self) -> &FacadeSpec {
        &self.spec
    }
    /// The fitted columns.
    pub fn columns(&self) -> &IntervalGroup {
        &self.columns
    }
    /// The fitted rows.
    pub fn rows(&self) -> &IntervalGroup {
        &self.rows
    }
    /// What had to be simplified (no skipped layers: the stack is not instantiated).
    pub fn report(&self) -> &FacadeReport {
        &self.report
    }
}

/// A style fitted to one face: evaluate it, rasterise it, or extract its cells.
#[derive(Debug, Clone)]
pub struct Facade {
    spec: FacadeSpec,
    columns: IntervalGroup,
    rows: IntervalGroup,
    stack: LayerStack,
    tint: f32,
    report: FacadeReport,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

impl PreparedStyle {
    /// Validates the style and draws its images.
    ///
    /// # Errors
    /// See [`FacadeStyle::validate`].
    pub fn new(style: FacadeStyle) -> Result<Self> {
        style.validate()?;
        let mut images = BTreeMap::new();
        style.stack.build_images("", &mut images)?;
        let salt = fnv1a(style.name.as_bytes());
        let rows = &style.rows;
        let rows_ground = AxisStyle {
            start: if rows.start.is_empty() {
                rows.module.clone()
            } else {
                rows.start.clone()
            },
            ..AxisStyle::default()
        };
        let rows_upper = AxisStyle {
            start: Vec::new(),
            min_repeats: rows.min_repeats.max(1),
            ..rows.clone()
        };
        let columns_sums = style.columns.sums();
        let rows_sums = [rows_ground.sums(), rows_upper.sums(), style.rows.sums()];
        Ok(PreparedStyle {
            style,
            images,
            salt,
            tiling: OnceLock::new(),
            rows_ground,
            rows_upper,
            columns_sums,
            rows_sums,
        })
    }

    pub(crate) fn tiling_cache(&self) -> &OnceLock<Arc<TileAnalysis>> {
        &self.tiling
    }

    /// The generator of a facade's randomness and its tint (its first draw).
    fn facade_rng(&self, spec: &FacadeSpec) -> (Pcg64Mcg, f32) {
        let mut rng = Pcg64Mcg::seed_from_u64(mix64(spec.seed ^ self.salt));
        let tint = {
            use rand::Rng;
            1.0 + self.style.tint_jitter * (2.0 * unit(rng.next_u64()) - 1.0)
        };
        (rng, tint)
    }

    /// The brightness factor [`facade`](Self::facade) gives the face of `spec`.
    pub fn tint_for(&self, spec: &FacadeSpec) -> f32 {
        self.facade_rng(spec).1
    }

    /// The style.
    pub fn style(&self) -> &FacadeStyle {
        &self.style
    }

    /// Fits the style to a face. Deterministic: the same style and spec give the same
    /// facade.
    ///
    /// A face narrower or lower than [`FacadeStyle::min_size`] gets a single blank column
    /// or row (walls, no windows), recorded in the [`FacadeReport`], rather than an error.
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`] for a bad spec; style errors from nested layers.
    pub fn facade(&self, spec: &FacadeSpec) -> Result<Facade> {
        let FacadeLayout {
            spec: _,
            columns,
            rows,
            mut report,
        } = self.layout(spec)?;
        let st = &self.style;
        let (mut rng, tint) = self.facade_rng(spec);
        let mut ctx = BuildContext {
            grid_u: Some(&columns),
            grid_v: Some(&rows),
            width: spec.width_m,
            height: spec.height_m,
            street: spec.role == FaceRole::Street,
            openings: spec.role != FaceRole::Blank,
            rng: &mut rng,
            depth: 0,
            images: Some(&self.images),
            path: String::new(),
        };
        let (stack, rep) = st.stack.instantiate(&mut ctx)?;
        report.skipped_layers = rep.skipped_layers;
        Ok(Facade {
            spec: *spec,
            columns,
            rows,
            stack,
            tint,
            report,
        })
    }

    /// The rows axis a face of `role` is fitted with.
    pub(crate) fn rows_style(&self, role: FaceRole) -> &AxisStyle {
        match role {
            FaceRole::GroundFloor => &self.rows_ground,
            FaceRole::UpperFloors => &self.rows_upper,
            _ => &self.style.rows,
        }
    }

    /// The fitting sums of the columns and of the rows `role` uses.
    pub(crate) fn sums(&self, role: FaceRole) -> (&AxisSums, &AxisSums) {
        let rows = match role {
            FaceRole::GroundFloor => &self.rows_sums[0],
            FaceRole::UpperFloors => &self.rows_sums[1],
            _ => &self.rows_sums[2],
        };
        (&self.columns_sums, rows)
    }

    /// Fits only the primary grid (columns and rows) of the style to a face: what
    /// [`Facade::tile_quads`] needs, without instantiating the layer stack. Much cheaper
    /// than [`facade`](Self::facade) when a city is textured with shared tile sets.
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`] for a bad spec.
    pub fn layout(&self, spec: &FacadeSpec) -> Result<FacadeLayout> {
        spec.validate()?;
        let st = &self.style;
        let rows_style = self.rows_style(spec.role);
        let wanted = self.sums(spec.role).1.wanted_rows(spec.floors);
        let mut report = FacadeReport::default();
        let fit = |axis: &AxisStyle, len: f64, wanted: Option<u32>, blank: &mut bool| match axis
            .fit(len, wanted)
        {
            Ok(g) => Ok(g),
            Err(FacadeError::TooShort { .. }) => {
                *blank = true;
                IntervalGroup::single(len, "blank", Profile::Off)
            }
            Err(e) => Err(e),
        };
        let columns = fit(&st.columns, spec.width_m, None, &mut report.blank_columns)?;
        let rows = fit(rows_style, spec.height_m, wanted, &mut report.blank_rows)?;
        report.floors = rows.floor_count();
        Ok(FacadeLayout {
            spec: *spec,
            columns,
            rows,
            report,
        })
    }
}

impl Facade {
    /// Fits `style` to `spec` in one call (validates the style and draws its images each
    /// time: for many facades use [`PreparedStyle`]).
    ///
    /// # Errors
    /// See [`PreparedStyle::new`] and [`PreparedStyle::facade`].
    pub fn new(style: &FacadeStyle, spec: &FacadeSpec) -> Result<Self> {
        PreparedStyle::new(style.clone())?.facade(spec)
    }

    /// The spec it was built for.
    pub fn spec(&self) -> &FacadeSpec {
        &self.spec
    }

    /// Its primary grid alone (for [`PreparedStyle::tile_plan`]).
    pub fn layout(&self) -> FacadeLayout {
        FacadeLayout {
            spec: self.spec,
            columns: self.columns.clone(),
            rows: self.rows.clone(),
            report: self.report.clone(),
        }
    }

    /// The fitted primary columns.
    pub fn columns(&self) -> &IntervalGroup {
        &self.columns
    }

    /// The fitted primary rows.
    pub fn rows(&self) -> &IntervalGroup {
        &self.rows
    }

    /// The layer stack.
    pub fn stack(&self) -> &LayerStack {
        &self.stack
    }

    /// What was simplified.
    pub fn report(&self) -> &FacadeReport {
        &self.report
    }

    /// The per-facade brightness factor.
    pub fn tint(&self) -> f32 {
        self.tint
    }

    /// The surface at `(s, t)` metres (`s` from the left edge, `t` up from the bottom):
    /// O(log n) per layer. Points outside the face give the stack's background.
    pub fn sample(&self, s: f64, t: f64) -> FacadeSample {
        let m = self.stack.sample(s, t);
        if self.tint == 1.0 {
            m
        } else {
            m.shade(self.tint)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;

    #[test]
    fn spec_validation() {
        assert!(FacadeSpec::new(f64::NAN, 10.0, 0).validate().is_err());
        assert!(FacadeSpec::new(10.0, -1.0, 0).validate().is_err());
        assert!(FacadeSpec::new(10.0, 1e9, 0).validate().is_err());
        assert!(FacadeSpec::new(10.0, 10.0, 0).validate().is_ok());
    }

    #[test]
    fn tiny_faces_get_blank_grids() {
        let p = PreparedStyle::new(builtin::brick_house()).unwrap();
        let f = p.facade(&FacadeSpec::new(0.5, 0.5, 1)).unwrap();
        assert!(f.report().blank_columns && f.report().blank_rows);
        // Still a wall.
        assert!(f.sample(0.25, 0.25).is_valid());
    }

    #[test]
    fn floors_follow_the_building() {
        let p = PreparedStyle::new(builtin::classic_stone()).unwrap();
        for floors in [2, 4, 6] {
            let spec = FacadeSpec {
                floors: Some(floors),
                ..FacadeSpec::new(20.0, 3.6 * floors as f64 + 2.0, 3)
            };
            assert_eq!(p.facade(&spec).unwrap().report().floors, floors as usize);
        }
    }

    #[test]
    fn roles_change_layers_and_rows() {
        let p = PreparedStyle::new(builtin::brick_house()).unwrap();
        let spec = FacadeSpec::new(12.0, 9.0, 5);
        let street = p.facade(&spec).unwrap();
        let side = p
            .facade(&FacadeSpec {
                role: FaceRole::Side,
                ..spec
            })
            .unwrap();
        let blank = p
            .facade(&FacadeSpec {
                role: FaceRole::Blank,
                ..spec
            })
            .unwrap();
        assert!(street.stack().layers().len() > side.stack().layers().len());
        assert!(side.stack().layers().len() > blank.stack().layers().len());
        let ground = p
            .facade(&FacadeSpec {
                role: FaceRole::GroundFloor,
                ..FacadeSpec::new(12.0, 3.5, 5)
            })
            .unwrap();
        assert!(
            ground
                .rows()
                .intervals()
                .iter()
                .all(|iv| iv.part == crate::interval::Part::Start)
        );
    }
}
