//! SVG map writer.
//!
//! [`write_svg`] draws a [`MapLayers`] as a plan: water, parks, blocks, lots, roads (by
//! class, at their true width, bridges with a casing, tunnels dashed under everything
//! else, larger classes over smaller ones) and
//! building footprints coloured by kind. One SVG user unit is one metre; the `y` axis is
//! flipped so that north (layout `+y`) is up; the drawing is translated so that the
//! selected layers' bounding box plus a margin starts at `(0, 0)`.
//!
//! ## Guarantees
//!
//! * The map is validated before anything is written ([`MapLayers::validate`]).
//! * Stable output: coordinates are written with a fixed number of decimals
//!   ([`SvgOptions::decimals`], trailing zeros dropped, never `-0`), features in input
//!   order (roads sorted stably by drawing order), so identical maps give identical bytes.
//! * Streaming: every path is written straight to the writer.
//! * Well-formed XML; user-provided text (colours, kind and class names) is escaped.
//!
//! Each layer is a `<g id="water|parks|blocks|lots|roads|footprints">`; features carry
//! `data-id` and a `class` (road class, building kind), so the file can be styled further
//! with CSS. Debug overlays ([`SvgDebug`], off by default) follow on top, each its own
//! `<g id="debug-…">`.

use std::io::Write;

use polis_geom::{DVec2, PolygonWithHoles};

use crate::ExportError;
use crate::map::{BuildingKind, LayerSet, MapLayers, RoadClass};

pub use debug::SvgDebug;

mod debug;

/// Colours (any SVG paint: `#rrggbb`, a name, …) and line widths of the map.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SvgStyle {
    /// Background. Default: `#f2efe9`.
    pub background: String,
    /// Water fill. Default: `#aad3df`.
    pub water: String,
    /// Park fill. Default: `#c8e6a0`.
    pub park: String,
    /// Block fill. Default: `#e0dcd4`.
    pub block: String,
    /// Lot outline. Default: `#b5aea3`.
    pub lot_stroke: String,
    /// Lot outline width in metres. Default: 0.3.
    pub lot_stroke_width_m: f64,
    /// Highway colour. Default: `#e8925a`.
    pub highway: String,
    /// Major road colour. Default: `#f6c96b`.
    pub major: String,
    /// Street colour. Default: `#ffffff`.
    pub street: String,
    /// Footpath colour. Default: `#d9a6a0`.
    pub footpath: String,
    /// Colour of other road classes. Default: `#cccccc`.
    pub other_road: String,
    /// Casing drawn under bridges. Default: `#5a5a5a`.
    pub bridge_casing: String,
    /// Casing width on each side of a bridge, metres. Default: 1.0.
    pub bridge_casing_m: f64,
    /// Residential footprints. Default: `#d9b99b`.
    pub residential: String,
    /// Commercial footprints. Default: `#c79ad1`.
    pub commercial: String,
    /// Industrial footprints. Default: `#a8a8b8`.
    pub industrial: String,
    /// Skyscraper footprints. Default: `#7f9fbf`.
    pub skyscraper: String,
    /// Other building kinds. Default: `#bbbbbb`.
    pub other_building: String,
    /// Footprint outline. Default: `#6b6257`.
    pub footprint_stroke: String,
    /// Footprint outline width in metres. Default: 0.25.
    pub footprint_stroke_width_m: f64,
}

impl Default for SvgStyle {
    fn default() -> Self {
        let s = |c: &str| c.to_string();
        SvgStyle {
            background: s("#f2efe9"),
            water: s("#aad3df"),
            park: s("#c8e6a0"),
            block: s("#e0dcd4"),
            lot_stroke: s("#b5aea3"),
            lot_stroke_width_m: 0.3,
            highway: s("#e8925a"),
            major: s("#f6c96b"),
            street: s("#ffffff"),
            footpath: s("#d9a6a0"),
            other_road: s("#cccccc"),
            bridge_casing: s("#5a5a5a"),
            bridge_casing_m: 1.0,
            residential: s("#d9b99b"),
            commercial: s("#c79ad1"),
            industrial: s("#a8a8b8"),
            skyscraper: s("#7f9fbf"),
            other_building: s("#bbbbbb"),
            footprint_stroke: s("#6b6257"),
            footprint_stroke_width_m: 0.25,
        }
    }
}

impl SvgStyle {
    /// The colour of a road class.
    pub fn road(&self, class: &RoadClass) -> &str {
        match class {
            RoadClass::Highway => &self.highway,
            RoadClass::Major => &self.major,
            RoadClass::Street => &self.street,
            RoadClass::Footpath => &self.footpath,
            RoadClass::Other(_) => &self.other_road,
        }
    }

    /// The fill of a building kind.
    pub fn building(&self, kind: &BuildingKind) -> &str {
        match kind {
            BuildingKind::Residential => &self.residential,
            BuildingKind::Commercial => &self.commercial,
            BuildingKind::Industrial => &self.industrial,
            BuildingKind::Skyscraper => &self.skyscraper,
            BuildingKind::Other(_) => &self.other_building,
        }
    }
}

/// Options of [`write_svg`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SvgOptions {
    /// Which layers to draw (they also decide the extent). Default: all.
    pub layers: LayerSet,
    /// Size of one metre in SVG pixels (`width`/`height` attributes; the `viewBox` is
    /// always in metres). Must be finite and > 0. Default: 1.0.
    pub pixels_per_metre: f64,
    /// Empty border around the drawing, metres (finite, ≥ 0). Default: 10.0.
    pub margin_m: f64,
    /// Decimals written per coordinate, 0 to 6 (2 = centimetres). Default: 2.
    pub decimals: u8,
    /// Colours and line widths.
    pub style: SvgStyle,
    /// Debug overlays drawn over everything (Kelly §5.4.1, §5.5.1). Default: none.
    pub debug: SvgDebug,
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            layers: LayerSet::ALL,
            pixels_per_metre: 1.0,
            margin_m: 10.0,
            decimals: 2,
            style: SvgStyle::default(),
            debug: SvgDebug::default(),
        }
    }
}

/// The largest [`SvgOptions::decimals`].
pub const MAX_DECIMALS: u8 = 6;

/// Length of a tunnel's dashes in the plan, metres.
pub const TUNNEL_DASH_M: f64 = 8.0;
/// Gap between a tunnel's dashes in the plan, metres.
pub const TUNNEL_GAP_M: f64 = 6.0;

/// Writes `map` as an SVG image to `out`.
///
/// ```
/// use polis_export::map::{MapLayers, MapRoad, RoadClass};
/// use polis_export::svg::{write_svg, SvgOptions};
/// use polis_export::geom::DVec2;
/// let mut map = MapLayers::default();
/// map.roads.push(MapRoad::new(vec![DVec2::ZERO, DVec2::new(50.0, 20.0)], RoadClass::Street, 6.0));
/// let mut svg = Vec::new();
/// write_svg(&map, &SvgOptions::default(), &mut svg)?;
/// let text = String::from_utf8(svg)?;
/// assert!(text.contains("<g id=\"roads\""));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_svg<W: Write>(
    map: &MapLayers,
    options: &SvgOptions,
    out: W,
) -> Result<(), ExportError> {
    let o = options;
    if !(o.pixels_per_metre.is_finite() && o.pixels_per_metre > 0.0) {
        return Err(ExportError::InvalidOption {
            name: "pixels_per_metre",
            reason: format!("{} must be finite and > 0", o.pixels_per_metre),
        });
    }
    if !(o.margin_m.is_finite() && o.margin_m >= 0.0) {
        return Err(ExportError::InvalidOption {
            name: "margin_m",
            reason: format!("{} must be finite and ≥ 0", o.margin_m),
        });
    }
    if o.decimals > MAX_DECIMALS {
        return Err(ExportError::InvalidOption {
            name: "decimals",
            reason: format!("{} is more than {MAX_DECIMALS}", o.decimals),
        });
    }
    for (name, w) in [
        ("style.lot_stroke_width_m", o.style.lot_stroke_width_m),
        ("style.bridge_casing_m", o.style.bridge_casing_m),
        (
            "style.footprint_stroke_width_m",
            o.style.footprint_stroke_width_m,
        ),
        ("debug.line_width_m", o.debug.line_width_m),
    ] {
        if !(w.is_finite() && w >= 0.0) {
            return Err(ExportError::InvalidOption {
                name,
                reason: format!("{w} must be finite and ≥ 0"),
            });
        }
    }
    map.validate()?;
    let (min, max) = map.bounds(o.layers).unwrap_or((DVec2::ZERO, DVec2::ZERO));
    let mut w = SvgWriter {
        out: std::io::BufWriter::with_capacity(1 << 16, out),
        origin: DVec2::new(min.x - o.margin_m, max.y + o.margin_m),
        decimals: o.decimals,
        num: String::with_capacity(32),
    };
    let size = max - min + DVec2::splat(2.0 * o.margin_m);
    w.body(map, o, size).map_err(ExportError::io("svg"))?;
    w.out.flush().map_err(ExportError::io("svg"))
}

struct SvgWriter<W: Write> {
    out: std::io::BufWriter<W>,
    /// The layout point drawn at SVG (0, 0): the top-left corner.
    origin: DVec2,
    decimals: u8,
    num: String,
}

impl<W: Write> SvgWriter<W> {
    fn body(&mut self, map: &MapLayers, o: &SvgOptions, size: DVec2) -> std::io::Result<()> {
        let s = &o.style;
        let (vw, vh) = (self.fmt(size.x), self.fmt(size.y));
        let (pw, ph) = (
            self.fmt(size.x * o.pixels_per_metre),
            self.fmt(size.y * o.pixels_per_metre),
        );
        let (ox, oy) = (self.fmt(self.origin.x), self.fmt(self.origin.y));
        let out = &mut self.out;
        writeln!(out, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
        writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{pw}" height="{ph}" viewBox="0 0 {vw} {vh}">"#
        )?;
        writeln!(
            out,
            "<!-- polis-export {}: 1 unit = 1 m, north up; layout point ({ox}, {oy}) is drawn at (0, 0) -->",
            env!("CARGO_PKG_VERSION")
        )?;
        writeln!(
            out,
            r#"<rect x="0" y="0" width="{vw}" height="{vh}" fill="{}"/>"#,
            esc(&s.background)
        )?;
        if o.layers.water {
            self.areas("water", &s.water, map.water.iter().map(|p| (None, p)))?;
        }
        if o.layers.parks {
            self.areas("parks", &s.park, map.parks.iter().map(|p| (None, p)))?;
        }
        if o.layers.blocks {
            self.areas(
                "blocks",
                &s.block,
                map.blocks.iter().map(|b| (Some(b.id), &b.polygon)),
            )?;
        }
        if o.layers.lots {
            let sw = self.fmt(s.lot_stroke_width_m);
            writeln!(
                self.out,
                r#"<g id="lots" fill="none" stroke="{}" stroke-width="{sw}" stroke-linejoin="round">"#,
                esc(&s.lot_stroke)
            )?;
            for l in &map.lots {
                write!(self.out, r#"<path data-id="{}" d=""#, l.id)?;
                self.polygon(&l.polygon)?;
                writeln!(self.out, r#""/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        if o.layers.roads {
            self.roads(map, s)?;
        }
        if o.layers.footprints {
            let sw = self.fmt(s.footprint_stroke_width_m);
            writeln!(
                self.out,
                r#"<g id="footprints" stroke="{}" stroke-width="{sw}" stroke-linejoin="round" fill-rule="evenodd">"#,
                esc(&s.footprint_stroke)
            )?;
            for f in &map.footprints {
                let h = self.fmt(f.height_m);
                write!(
                    self.out,
                    r#"<path data-id="{}" class="{}" data-height="{h}" fill="{}" d=""#,
                    f.id,
                    esc(f.kind.as_str()),
                    esc(s.building(&f.kind))
                )?;
                self.polygon(&f.polygon)?;
                writeln!(self.out, r#""/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        self.debug(map, &o.debug)?;
        writeln!(self.out, "</svg>")
    }

    fn areas<'a>(
        &mut self,
        id: &str,
        fill: &str,
        items: impl Iterator<Item = (Option<u64>, &'a PolygonWithHoles)>,
    ) -> std::io::Result<()> {
        writeln!(
            self.out,
            r#"<g id="{id}" fill="{}" stroke="none" fill-rule="evenodd">"#,
            esc(fill)
        )?;
        for (fid, p) in items {
            match fid {
                Some(i) => write!(self.out, r#"<path data-id="{i}" d=""#)?,
                None => write!(self.out, r#"<path d=""#)?,
            }
            self.polygon(p)?;
            writeln!(self.out, r#""/>"#)?;
        }
        writeln!(self.out, "</g>")
    }

    fn roads(&mut self, map: &MapLayers, s: &SvgStyle) -> std::io::Result<()> {
        writeln!(
            self.out,
            r#"<g id="roads" fill="none" stroke-linecap="round" stroke-linejoin="round">"#
        )?;
        // Tunnels under everything, bridges over everything, larger classes over smaller;
        // input order otherwise.
        let mut order: Vec<usize> = (0..map.roads.len()).collect();
        order.sort_by_key(|&i| {
            let r = &map.roads[i];
            (r.bridge, !r.tunnel, r.class.rank())
        });
        for i in order {
            let r = &map.roads[i];
            if r.bridge {
                let cw = self.fmt(r.width_m + 2.0 * s.bridge_casing_m);
                write!(
                    self.out,
                    r#"<path data-id="{}" class="bridge-casing" stroke="{}" stroke-width="{cw}" stroke-linecap="butt" d=""#,
                    r.id,
                    esc(&s.bridge_casing)
                )?;
                self.polyline(&r.points)?;
                writeln!(self.out, r#""/>"#)?;
            }
            let width = self.fmt(r.width_m);
            let bridge = if r.bridge { " bridge" } else { "" };
            // A tunnel: dashes of TUNNEL_DASH_M every TUNNEL_DASH_M + TUNNEL_GAP_M.
            let tunnel = if r.tunnel {
                format!(
                    r#" stroke-dasharray="{} {}" stroke-linecap="butt""#,
                    self.fmt(TUNNEL_DASH_M),
                    self.fmt(TUNNEL_GAP_M)
                )
            } else {
                String::new()
            };
            let class = if r.tunnel { " tunnel" } else { "" };
            write!(
                self.out,
                r#"<path data-id="{}" class="{}{bridge}{class}" stroke="{}" stroke-width="{width}"{tunnel} d=""#,
                r.id,
                esc(r.class.as_str()),
                esc(s.road(&r.class))
            )?;
            self.polyline(&r.points)?;
            writeln!(self.out, r#""/>"#)?;
        }
        writeln!(self.out, "</g>")
    }

    fn polygon(&mut self, p: &PolygonWithHoles) -> std::io::Result<()> {
        for (k, (_, ring)) in p.rings().enumerate() {
            if k > 0 {
                self.out.write_all(b" ")?;
            }
            self.polyline(ring.points())?;
            self.out.write_all(b" Z")?;
        }
        Ok(())
    }

    fn polyline(&mut self, points: &[DVec2]) -> std::io::Result<()> {
        for (k, &p) in points.iter().enumerate() {
            let x = p.x - self.origin.x;
            let y = self.origin.y - p.y;
            self.out.write_all(if k == 0 { b"M" } else { b" L" })?;
            self.num.clear();
            fixed(&mut self.num, x, self.decimals);
            self.num.push(' ');
            fixed(&mut self.num, y, self.decimals);
            self.out.write_all(self.num.as_bytes())?;
        }
        Ok(())
    }

    fn fmt(&self, v: f64) -> String {
        let mut s = String::new();
        fixed(&mut s, v, self.decimals);
        s
    }
}

/// Appends `v` rounded to `decimals` places (half away from zero), without trailing zeros
/// or a trailing point, and never as `-0`. Exact decimal digits: the value is rounded once,
/// in integer units of `10^-decimals`.
pub(crate) fn fixed(out: &mut String, v: f64, decimals: u8) {
    use std::fmt::Write as _;
    let scale = 10i64.pow(u32::from(decimals.min(MAX_DECIMALS)));
    let units = (v * scale as f64).round();
    // Validated coordinates stay below 1e8 m, so units < 1e15 fit i64 exactly.
    let units = units.clamp(-9.0e17, 9.0e17) as i64;
    if units < 0 {
        out.push('-');
    }
    let a = units.unsigned_abs();
    let s = scale as u64;
    let _ = write!(out, "{}", a / s);
    let mut frac = a % s;
    if frac != 0 {
        let mut digits = usize::from(decimals);
        while frac.is_multiple_of(10) {
            frac /= 10;
            digits -= 1;
        }
        let _ = write!(out, ".{frac:0digits$}");
    }
}

/// Escapes text for an XML attribute value in double quotes.
pub(crate) fn esc(s: &str) -> std::borrow::Cow<'_, str> {
    let plain = |c: char| !matches!(c, '&' | '<' | '>' | '"' | '\'') && !bad_xml_char(c);
    if s.chars().all(plain) {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if bad_xml_char(c) => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Characters XML 1.0 does not allow (C0 controls but tab, line feed, carriage return).
fn bad_xml_char(c: char) -> bool {
    (c < ' ' && !matches!(c, '\t' | '\n' | '\r')) || matches!(c, '\u{FFFE}' | '\u{FFFF}')
}

#[cfg(test)]
mod tests;
