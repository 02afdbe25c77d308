//! The readable text table of a [`CityReport`] (its `Display`).

use std::fmt::{self, Display, Formatter, Write};

use crate::CityReport;
use crate::realism::Realism;
use crate::summary::{Distribution, Histogram};

/// `count  median [p10 – p90]  mean` of a distribution, with `unit`.
fn dist(d: &Distribution, unit: &str, digits: usize) -> String {
    if d.count == 0 {
        return "—".into();
    }
    format!(
        "median {:.*}{unit} [p10 {:.*} – p90 {:.*}], mean {:.*}, max {:.*} (n = {})",
        digits, d.median, digits, d.p10, digits, d.p90, digits, d.mean, digits, d.max, d.count
    )
}

fn hist(h: &Histogram) -> String {
    let mut s = String::new();
    for (i, c) in h.counts.iter().enumerate() {
        if i > 0 {
            s.push_str("  ");
        }
        let lo = h.edges.get(i).copied().unwrap_or(0.0);
        let _ = match h.edges.get(i + 1) {
            Some(hi) => write!(s, "{lo}–{hi}: {c}"),
            None => write!(s, "≥{lo}: {c}"),
        };
    }
    s
}

fn row(f: &mut Formatter<'_>, name: &str, value: impl Display) -> fmt::Result {
    writeln!(f, "  {name:<30} {value}")
}

impl Display for Realism {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "realism against {} ({}): {} in band, {} out",
            self.city, self.region, self.in_band, self.out_of_band
        )?;
        writeln!(
            f,
            "  {:<18} {:>10} {:>10} {:>8}  verdict",
            "metric", "polis", "real", "band"
        )?;
        for r in &self.rows {
            let real = r.real.map_or("—".into(), |x| format!("{x:.3}"));
            let band = r.band.map_or("".into(), |b| b.to_string());
            let verdict = match r.in_band {
                Some(true) => "in",
                Some(false) => "OUT",
                None => "",
            };
            writeln!(
                f,
                "  {:<18} {:>10.3} {:>10} {:>8}  {verdict}",
                r.metric, r.polis, real, band
            )?;
        }
        Ok(())
    }
}

impl Display for CityReport {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let s = &self.streets;
        writeln!(f, "streets (simplified graph)")?;
        row(
            f,
            "nodes / streets / segments",
            format!("{} / {} / {}", s.nodes, s.streets, s.segments),
        )?;
        row(
            f,
            "isolated / zero-length / loops",
            format!(
                "{} / {} / {}",
                s.isolated_nodes, s.zero_length_edges, s.self_loops
            ),
        )?;
        row(
            f,
            "orientation order φ",
            format!("{:.3}", s.orientation_order),
        )?;
        row(
            f,
            "entropy H_o / H_w",
            format!(
                "{:.3} / {:.3}",
                s.orientation_entropy, s.weighted_orientation_entropy
            ),
        )?;
        row(f, "average degree k̄", format!("{:.3}", s.average_degree))?;
        row(
            f,
            "dead end / 3 / 4 / 5+ way",
            format!(
                "{:.3} / {:.3} / {:.3} / {:.3}",
                s.share_dead_end, s.share_3way, s.share_4way, s.share_5plus
            ),
        )?;
        row(f, "segment length", dist(&s.segment_length_m, " m", 1))?;
        row(f, "circuity", format!("{:.4}", s.circuity))?;
        row(
            f,
            "bridges",
            format!("{} ({:.0} m)", s.bridges, s.bridge_length_m),
        )?;
        row(
            f,
            "length / highway share",
            format!("{:.1} km / {:.3}", s.total_length_km, s.highway_share),
        )?;
        row(
            f,
            "intersections per km² of land",
            format!(
                "{:.1} ({} on {:.2} km²)",
                s.intersection_density_per_km2, s.intersections, s.land_area_km2
            ),
        )?;
        match &s.grade {
            Some(g) => row(
                f,
                "grade median / mean / max",
                format!(
                    "{:.3} / {:.3} / {:.3} ({:.1} % of length > 10 %)",
                    g.median,
                    g.mean_weighted,
                    g.max,
                    g.share_steeper_10pct * 100.0
                ),
            )?,
            None => row(f, "grade", "no elevation")?,
        }
        let b = &self.blocks;
        writeln!(f, "blocks")?;
        row(
            f,
            "count (degenerate)",
            format!("{} ({})", b.count, b.degenerate),
        )?;
        row(f, "area", dist(&b.area_m2, " m²", 0))?;
        row(f, "shape factor Φ", dist(&b.shape_factor, "", 3))?;
        row(f, "Φ histogram", hist(&b.shape_factor_histogram))?;
        row(
            f,
            "long axis (order)",
            format!("{:.1}° ({:.2})", b.long_axis_deg, b.long_axis_order),
        )?;
        let l = &self.lots;
        writeln!(f, "lots")?;
        row(
            f,
            "count (street access share)",
            format!("{} ({:.3})", l.count, l.street_access_share),
        )?;
        row(f, "area", dist(&l.area_m2, " m²", 0))?;
        row(f, "frontage", dist(&l.frontage_m, " m", 1))?;
        row(f, "depth", dist(&l.depth_m, " m", 1))?;
        let bu = &self.buildings;
        writeln!(f, "buildings")?;
        row(f, "count", bu.count)?;
        row(
            f,
            "coverage of lots / of land",
            format!("{:.3} / {:.3}", bu.coverage, bu.ground_coverage),
        )?;
        row(f, "floor-area ratio", format!("{:.2}", bu.floor_area_ratio))?;
        row(f, "height", dist(&bu.height_m, " m", 1))?;
        row(f, "height histogram (m)", hist(&bu.height_histogram))?;
        let kinds: Vec<String> = bu
            .kinds
            .iter()
            .map(|(k, n)| {
                format!(
                    "{k} {n} ({:.0} %)",
                    100.0 * crate::summary::ratio(*n as f64, bu.count as f64)
                )
            })
            .collect();
        row(f, "kinds", kinds.join(", "))?;
        let d = &self.defects;
        writeln!(f, "plan defects")?;
        row(
            f,
            "road segments inside blocks",
            format!(
                "{} ({:.0} m), {} without lots ({:.0} m unserved)",
                d.segments_inside_blocks,
                d.length_inside_blocks_m,
                d.segments_inside_blocks_without_lots,
                d.length_inside_blocks_without_lots_m
            ),
        )?;
        row(
            f,
            "dead ends: edge / water / land",
            format!(
                "{} / {} / {} of {}",
                d.stubs_at_map_edge, d.stubs_in_water, d.stubs_in_land, d.stubs
            ),
        )?;
        row(
            f,
            "stubs in land without lots",
            d.stubs_in_land_without_lots,
        )?;
        row(
            f,
            "buildings in a road corridor",
            format!(
                "{} ({:.2} %)",
                d.buildings_in_road_corridor,
                d.buildings_in_road_corridor_share * 100.0
            ),
        )?;
        let w = &self.earthworks;
        if w.cut_m3 > 0.0 || w.fill_m3 > 0.0 {
            writeln!(f, "earthworks (roads graded into the land)")?;
            row(
                f,
                "cut / fill",
                format!("{:.0} m³ / {:.0} m³", w.cut_m3, w.fill_m3),
            )?;
            row(
                f,
                "road off the ground / steepest",
                format!(
                    "{:.0} m / {:.1} %",
                    w.moved_length_m,
                    w.steepest_grade * 100.0
                ),
            )?;
        }
        if let Some(r) = &self.realism {
            write!(f, "{r}")?;
        }
        Ok(())
    }
}
