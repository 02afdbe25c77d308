//! Kelly's primary road network drawn as SVG, one file per scene in `out/`:
//!
//! * `primary_fig40.svg`: Fig. 40, adaptive roads between the same two nodes over a hill
//!   with each strategy (blue: minimum elevation, red: least elevation difference,
//!   green: even elevation difference, grey: straight), with every fan of samples (thin
//!   lines, dots; the chosen sample ringed);
//! * `primary_milan.svg`: Milan's concentric rings and radials (§6.1, Fig. 81), built by
//!   edits: radials crossing the rings get junctions from validity checking;
//! * `primary_paris.svg`: the spokes around the Arc de Triomphe (§6.1, Fig. 82), with a
//!   middle ring whose ends snap onto the spokes as T-junctions.
//!
//! Roads are drawn over the terrain (darker = higher); control nodes red, plot points
//! orange (Kelly's Fig. 38 colours).
//!
//! Run with `cargo run -p polis-roads --release --example primary_roads`.

#![allow(clippy::unwrap_used)]

use std::fmt::Write as _;
use std::sync::Arc;

use polis_geom::field::{Fbm, FbmParams, FnField};
use polis_geom::{Aabb2, DVec2, Field, FieldExt};
use polis_roads::primary::{
    AdaptiveParams, ControlId, Edit, EditOptions, Endpoint, PrimaryEditor, PrimaryNetwork,
    RoadPreset, Strategy, Terrain, plot_path, plot_traced,
};

/// An SVG canvas over a map box, 1000 px on its longer side.
struct Canvas {
    min: DVec2,
    max: DVec2,
    scale: f64,
    s: String,
}

impl Canvas {
    fn new(b: Aabb2, terrain: &Terrain) -> Self {
        let size = b.max - b.min;
        let scale = 1000.0 / size.x.max(size.y);
        let (w, h) = (size.x * scale, size.y * scale);
        let mut c = Canvas {
            min: b.min,
            max: b.max,
            scale,
            s: String::new(),
        };
        let _ = writeln!(
            c.s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.1} {h:.1}">"#
        );
        // Elevation shading on a 100 × 100 grid.
        let n = 100;
        let cell = size / f64::from(n);
        let mut hs = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let p = b.min + cell * DVec2::new(f64::from(i) + 0.5, f64::from(j) + 0.5);
                hs.push((p, terrain.elevation(p)));
            }
        }
        let lo = hs.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
        let hi = hs.iter().map(|x| x.1).fold(f64::NEG_INFINITY, f64::max);
        for (p, h) in hs {
            let t = if hi > lo { (h - lo) / (hi - lo) } else { 0.0 };
            let mut rgb = [
                (236.0 - 90.0 * t) as u8,
                (240.0 - 80.0 * t) as u8,
                (226.0 - 100.0 * t) as u8,
            ];
            if terrain.point(p) == Some(polis_roads::legality::Illegal::Water) {
                rgb = [150, 190, 230];
            } else if terrain.point(p) == Some(polis_roads::legality::Illegal::Park) {
                rgb = [170, 210, 150];
            }
            let (x, y) = c.map(p - cell * 0.5 + DVec2::new(0.0, cell.y));
            let _ = writeln!(
                c.s,
                r#"<rect x="{x:.2}" y="{y:.2}" width="{:.2}" height="{:.2}" fill="rgb({},{},{})"/>"#,
                cell.x * scale + 0.3,
                cell.y * scale + 0.3,
                rgb[0],
                rgb[1],
                rgb[2]
            );
        }
        c
    }

    fn map(&self, p: DVec2) -> (f64, f64) {
        (
            (p.x - self.min.x) * self.scale,
            (self.max.y - p.y) * self.scale,
        )
    }

    fn polyline(&mut self, pts: &[DVec2], colour: &str, width_px: f64, extra: &str) {
        let mut d = String::new();
        for &p in pts {
            let (x, y) = self.map(p);
            let _ = write!(d, "{x:.2},{y:.2} ");
        }
        let _ = writeln!(
            self.s,
            r#"<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="{width_px:.2}" stroke-linecap="round" stroke-linejoin="round" {extra}/>"#
        );
    }

    fn dot(&mut self, p: DVec2, r: f64, fill: &str, stroke: &str) {
        let (x, y) = self.map(p);
        let _ = writeln!(
            self.s,
            r#"<circle cx="{x:.2}" cy="{y:.2}" r="{r:.2}" fill="{fill}" stroke="{stroke}" stroke-width="1"/>"#
        );
    }

    fn text(&mut self, x: f64, y: f64, t: &str, colour: &str) {
        let _ = writeln!(
            self.s,
            r#"<text x="{x:.0}" y="{y:.0}" font-family="sans-serif" font-size="16" fill="{colour}">{t}</text>"#
        );
    }

    /// Every road of `net` (bridges darker), its plot points and the control nodes.
    fn network(&mut self, net: &PrimaryNetwork) {
        for (_, r) in net.roads() {
            let colour = match r.spec.class {
                RoadPreset::Motorway => "rgb(200,60,40)",
                RoadPreset::Primary => "rgb(230,140,40)",
                RoadPreset::InnerCity => "rgb(90,90,90)",
            };
            let w = (r.spec.width_m * self.scale).max(1.5);
            self.polyline(&r.path.points, colour, w, "");
            for (k, seg) in r.path.points.windows(2).enumerate() {
                if r.path.bridge[k] {
                    self.polyline(seg, "rgb(40,40,120)", w, "");
                }
            }
            for p in r.path.plot_points() {
                self.dot(p, 1.6, "rgb(255,150,0)", "none");
            }
        }
        for (_, n) in net.nodes() {
            self.dot(n.pos, 4.0, "rgb(220,20,20)", "white");
        }
    }

    fn finish(mut self, path: &str) {
        self.s.push_str("</svg>\n");
        std::fs::write(path, self.s).unwrap();
        println!("wrote {path}");
    }
}

/// Fig. 40: the strategies between the same two nodes over a hill.
fn fig40() {
    let b = Aabb2::new(DVec2::new(-1300.0, -900.0), DVec2::new(1300.0, 900.0));
    let hill = Fbm::new(FbmParams {
        seed: 4,
        octaves: 3,
        wavelength_m: 700.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(8.0);
    let f = FnField::new(move |p: DVec2| {
        90.0 * (-(p - DVec2::new(0.0, 60.0)).length_squared() / (2.0 * 330.0 * 330.0)).exp()
            + 110.0 / (1.0 + (-p.x / 300.0).exp())
            + hill.sample(p)
    });
    let terrain = Terrain::with_elevation(Arc::new(f), b).unwrap();
    let mut c = Canvas::new(b, &terrain);
    let (a, z) = (DVec2::new(-1100.0, -50.0), DVec2::new(1100.0, 80.0));
    let runs = [
        (Strategy::Straight, "rgb(120,120,120)"),
        (Strategy::MinimumElevation, "rgb(30,80,230)"),
        (Strategy::MinimumElevationDifference, "rgb(220,30,30)"),
        (Strategy::EvenElevationDifference, "rgb(20,160,40)"),
    ];
    let mut trace = Vec::new();
    for (k, (s, colour)) in runs.iter().enumerate() {
        let p = AdaptiveParams {
            strategy: *s,
            sample_size_m: 110.0,
            samples: 7,
            deviation_deg: 35.0,
            snap_m: 110.0,
            segment_draw_size_m: 8.0,
            max_bridge_m: 0.0,
        };
        plot_traced(a, z, &p, &terrain, &mut trace).unwrap();
        if *s != Strategy::Straight {
            for fan in &trace {
                for (i, &q) in fan.samples.iter().enumerate() {
                    c.polyline(&[fan.from, q], colour, 0.6, r#"opacity="0.45""#);
                    let r = if i == fan.chosen { 3.2 } else { 1.8 };
                    c.dot(q, r, if i == fan.chosen { "white" } else { colour }, colour);
                }
            }
        }
        let path = plot_path(a, z, &p, &terrain).unwrap();
        c.polyline(&path.points, colour, 3.0, "");
        let label = format!("{s:?}: max grade {:.1} %", 100.0 * path.max_grade());
        c.text(20.0, 28.0 + 22.0 * k as f64, &label, colour);
        println!("  fig40 {label}");
    }
    c.dot(a, 6.0, "rgb(220,20,20)", "white");
    c.dot(z, 6.0, "rgb(220,20,20)", "white");
    c.finish("out/primary_fig40.svg");
}

/// Applies `edit`, counting a refusal instead of failing (and saying why).
fn try_apply(ed: &mut PrimaryEditor, edit: &Edit, refused: &mut usize) -> Option<ControlId> {
    match ed.propose(edit) {
        Ok(p) => {
            let end = p.end_node();
            ed.commit(&p).unwrap();
            end
        }
        Err(e) => {
            *refused += 1;
            println!("  refused: {e}");
            None
        }
    }
}

fn gentle_terrain(b: Aabb2, seed: u64, amp: f64) -> Terrain {
    let f = Fbm::new(FbmParams {
        seed,
        octaves: 4,
        wavelength_m: 1500.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(amp);
    Terrain::with_elevation(f.shared(), b).unwrap()
}

fn polar(r: f64, deg: f64) -> DVec2 {
    DVec2::from_angle(deg.to_radians()) * r
}

/// Milan (Fig. 81): three concentric rings and eight radials, about 5 km × 5 km.
fn milan() {
    let b = Aabb2::new(DVec2::splat(-2500.0), DVec2::splat(2500.0));
    let terrain = gentle_terrain(b, 21, 25.0);
    let mut ed = PrimaryEditor::new(terrain.clone(), EditOptions::default()).unwrap();
    let mut refused = 0;
    let inner = RoadPreset::InnerCity.spec();
    let primary = RoadPreset::Primary.spec();
    let mut rings = Vec::new();
    for (r, n, phase, spec) in [
        (450.0, 8, 22.5, inner),
        (1000.0, 12, 15.0, inner),
        (1700.0, 16, 11.25, primary),
    ] {
        let mut ids = Vec::new();
        for k in 0..n {
            ids.push(ed.network().next_node_id());
            let at = polar(r, phase + 360.0 * f64::from(k) / f64::from(n));
            try_apply(&mut ed, &Edit::AddNode { at, label: None }, &mut refused);
        }
        for k in 0..ids.len() {
            let (from, to) = (
                Endpoint::Node(ids[k]),
                Endpoint::Node(ids[(k + 1) % ids.len()]),
            );
            try_apply(&mut ed, &Edit::AddRoad { from, to, spec }, &mut refused);
        }
        rings.push(ids);
    }
    // Radials: from each inner-ring node out past the outer ring, crossing the rings.
    for (k, &node) in rings[0].iter().enumerate() {
        let from = Endpoint::Node(node);
        let to = Endpoint::At(polar(2300.0, 22.5 + 45.0 * k as f64));
        try_apply(
            &mut ed,
            &Edit::AddRoad {
                from,
                to,
                spec: primary,
            },
            &mut refused,
        );
    }
    ed.network().check_invariants().unwrap();
    println!(
        "  milan: {} nodes, {} roads, {} refused edits",
        ed.network().node_count(),
        ed.network().road_count(),
        refused
    );
    let mut c = Canvas::new(b, &terrain);
    c.network(ed.network());
    c.finish("out/primary_milan.svg");
}

/// Paris (Fig. 82): twelve avenues around the Étoile, about 1.3 km × 1.3 km.
fn paris() {
    let b = Aabb2::new(DVec2::splat(-650.0), DVec2::splat(650.0));
    let terrain = gentle_terrain(b, 5, 12.0);
    let mut ed = PrimaryEditor::new(terrain.clone(), EditOptions::default()).unwrap();
    let mut refused = 0;
    let mut spec = RoadPreset::InnerCity.spec();
    spec.params.sample_size_m = 60.0;
    spec.params.snap_m = 60.0;
    spec.params.deviation_deg = 12.0;
    let mut place = Vec::new();
    for k in 0..12 {
        place.push(ed.network().next_node_id());
        try_apply(
            &mut ed,
            &Edit::AddNode {
                at: polar(90.0, 30.0 * f64::from(k)),
                label: None,
            },
            &mut refused,
        );
    }
    for k in 0..12 {
        let (from, to) = (
            Endpoint::Node(place[k]),
            Endpoint::Node(place[(k + 1) % 12]),
        );
        try_apply(&mut ed, &Edit::AddRoad { from, to, spec }, &mut refused);
    }
    // The avenues, chained outward in two legs each.
    let mut outer = Vec::new();
    for (k, &node) in place.iter().enumerate() {
        let a = 30.0 * k as f64;
        let mid = try_apply(
            &mut ed,
            &Edit::Chain {
                from: node,
                to: polar(330.0, a + 2.0),
                spec,
            },
            &mut refused,
        );
        if let Some(mid) = mid {
            outer.push(try_apply(
                &mut ed,
                &Edit::Chain {
                    from: mid,
                    to: polar(600.0, a - 3.0),
                    spec,
                },
                &mut refused,
            ));
        }
    }
    // A ring through the avenues' middle nodes, and an outer boulevard whose ends snap
    // onto the avenues (T-junctions) a little inside their ends.
    for k in 0..12 {
        let (a, z) = (30.0 * k as f64, 30.0 * (k + 1) as f64);
        let near = |deg: f64| -> DVec2 {
            // The avenue's path point nearest to radius 480 m.
            let want = polar(480.0, deg);
            let net = ed.network();
            net.roads()
                .flat_map(|(_, r)| r.path.points.iter().copied())
                .min_by(|p, q| p.distance(want).total_cmp(&q.distance(want)))
                .unwrap_or(want)
        };
        let (pa, pz) = (near(a), near(z));
        try_apply(
            &mut ed,
            &Edit::AddRoad {
                from: Endpoint::At(pa),
                to: Endpoint::At(pz),
                spec,
            },
            &mut refused,
        );
    }
    ed.network().check_invariants().unwrap();
    println!(
        "  paris: {} nodes, {} roads, {} refused edits, {} avenue ends",
        ed.network().node_count(),
        ed.network().road_count(),
        refused,
        outer.len()
    );
    let mut c = Canvas::new(b, &terrain);
    c.network(ed.network());
    c.finish("out/primary_paris.svg");
}

fn main() {
    std::fs::create_dir_all("out").unwrap();
    fig40();
    milan();
    paris();
}
