//! The SVG writer's debug overlays: what Kelly's debug views show (Citygen §5.4.1, the
//! primary roads' plot samples and fans; §5.5.1, block and lot boundaries and the lot
//! subdivision's split lines in order).

use std::io::Write;

use super::{SvgWriter, esc};
use crate::map::MapLayers;

/// Which debug overlays the SVG writer draws over the map, and in what colours. Each
/// overlay is a group of its own (`<g id="debug-plot">`, `debug-fans`, `debug-blocks`,
/// `debug-lots`, `debug-splits`), drawn in that order over every map layer.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SvgDebug {
    /// The primary roads' plot points, as dots. Default: false.
    pub plot_points: bool,
    /// The primary roads' sample fans: a line from the head to each sample, the chosen
    /// one emphasised. Default: false.
    pub fans: bool,
    /// Block boundaries as outlines. Default: false.
    pub blocks: bool,
    /// Lot boundaries as outlines. Default: false.
    pub lots: bool,
    /// The lot subdivision's split lines, each with `data-order` (its place in the
    /// subdivision order of the whole map) and `data-block`. Default: false.
    pub splits: bool,
    /// Colour of plot points and chosen samples. Default: `#d62728`.
    pub plot_colour: String,
    /// Colour of the other samples. Default: `#9e9e9e`.
    pub fan_colour: String,
    /// Block outline colour. Default: `#1f77b4`.
    pub block_colour: String,
    /// Lot outline colour. Default: `#2ca02c`.
    pub lot_colour: String,
    /// Split line colour. Default: `#9467bd`.
    pub split_colour: String,
    /// Width of the debug lines, metres (finite, ≥ 0). Default: 0.5.
    pub line_width_m: f64,
}

impl Default for SvgDebug {
    fn default() -> Self {
        let s = |c: &str| c.to_string();
        SvgDebug {
            plot_points: false,
            fans: false,
            blocks: false,
            lots: false,
            splits: false,
            plot_colour: s("#d62728"),
            fan_colour: s("#9e9e9e"),
            block_colour: s("#1f77b4"),
            lot_colour: s("#2ca02c"),
            split_colour: s("#9467bd"),
            line_width_m: 0.5,
        }
    }
}

impl SvgDebug {
    /// Every overlay on, default colours.
    pub fn all() -> Self {
        SvgDebug {
            plot_points: true,
            fans: true,
            blocks: true,
            lots: true,
            splits: true,
            ..SvgDebug::default()
        }
    }

    /// Whether any overlay is on.
    pub fn any(&self) -> bool {
        self.plot_points || self.fans || self.blocks || self.lots || self.splits
    }
}

/// `"plot,fans,blocks,lots,splits"` (any of them, case-insensitive, comma-separated),
/// `"all"` or `"none"`: the overlays to turn on, default colours.
impl std::str::FromStr for SvgDebug {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let mut out = SvgDebug::default();
        for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            match part.to_ascii_lowercase().as_str() {
                "plot" => out.plot_points = true,
                "fans" => out.fans = true,
                "blocks" => out.blocks = true,
                "lots" => out.lots = true,
                "splits" => out.splits = true,
                "all" => out = SvgDebug::all(),
                "none" => out = SvgDebug::default(),
                other => {
                    return Err(format!(
                        "unknown debug layer {other:?}; give a comma-separated list of plot, \
                         fans, blocks, lots, splits (or all, none)"
                    ));
                }
            }
        }
        Ok(out)
    }
}

impl<W: Write> SvgWriter<W> {
    pub(super) fn debug(&mut self, map: &MapLayers, d: &SvgDebug) -> std::io::Result<()> {
        let sw = self.fmt(d.line_width_m.max(0.0));
        let dot = self.fmt(d.line_width_m.max(0.0) * 2.0);
        if d.plot_points {
            writeln!(
                self.out,
                r#"<g id="debug-plot" fill="{}" stroke="none">"#,
                esc(&d.plot_colour)
            )?;
            for &p in &map.debug.plot_points {
                let (x, y) = self.xy(p);
                writeln!(self.out, r#"<circle cx="{x}" cy="{y}" r="{dot}"/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        if d.fans {
            writeln!(
                self.out,
                r#"<g id="debug-fans" fill="none" stroke="{}" stroke-width="{sw}">"#,
                esc(&d.fan_colour)
            )?;
            for (i, f) in map.debug.fans.iter().enumerate() {
                write!(self.out, r#"<path data-fan="{i}" d=""#)?;
                for (k, &s) in f.samples.iter().enumerate() {
                    if k > 0 {
                        self.out.write_all(b" ")?;
                    }
                    self.polyline(&[f.from, s])?;
                }
                writeln!(self.out, r#""/>"#)?;
                if let Some(&c) = f.samples.get(f.chosen) {
                    write!(
                        self.out,
                        r#"<path class="chosen" data-fan="{i}" stroke="{}" d=""#,
                        esc(&d.plot_colour)
                    )?;
                    self.polyline(&[f.from, c])?;
                    writeln!(self.out, r#""/>"#)?;
                }
            }
            writeln!(self.out, "</g>")?;
        }
        if d.blocks {
            writeln!(
                self.out,
                r#"<g id="debug-blocks" fill="none" stroke="{}" stroke-width="{sw}">"#,
                esc(&d.block_colour)
            )?;
            for b in &map.blocks {
                write!(self.out, r#"<path data-id="{}" d=""#, b.id)?;
                self.polygon(&b.polygon)?;
                writeln!(self.out, r#""/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        if d.lots {
            writeln!(
                self.out,
                r#"<g id="debug-lots" fill="none" stroke="{}" stroke-width="{sw}">"#,
                esc(&d.lot_colour)
            )?;
            for l in &map.lots {
                write!(self.out, r#"<path data-id="{}" d=""#, l.id)?;
                self.polygon(&l.polygon)?;
                writeln!(self.out, r#""/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        if d.splits {
            writeln!(
                self.out,
                r#"<g id="debug-splits" fill="none" stroke="{}" stroke-width="{sw}" stroke-dasharray="{dot}">"#,
                esc(&d.split_colour)
            )?;
            for (i, s) in map.debug.splits.iter().enumerate() {
                write!(
                    self.out,
                    r#"<path class="split" data-order="{i}" data-block="{}" d=""#,
                    s.block
                )?;
                for (k, c) in s.chords.iter().enumerate() {
                    if k > 0 {
                        self.out.write_all(b" ")?;
                    }
                    self.polyline(c)?;
                }
                writeln!(self.out, r#""/>"#)?;
            }
            writeln!(self.out, "</g>")?;
        }
        Ok(())
    }

    /// A layout point in SVG coordinates, formatted.
    fn xy(&self, p: polis_geom::DVec2) -> (String, String) {
        (self.fmt(p.x - self.origin.x), self.fmt(self.origin.y - p.y))
    }
}
