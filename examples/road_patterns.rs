//! Road networks of Parish & Müller's extended L-system, one SVG per scene in `out/`:
//! each pattern alone (Basic, New York, Paris, San Francisco), New York and Paris blended
//! by pattern-weight maps (paper Fig. 7), and a Manhattan-like island with water, a
//! coastal highway and bridges.
//!
//! Run with `cargo run -p polis --release --example road_patterns`.

use std::fmt::Write as _;
use std::sync::Arc;

use polis::geom::field::{Constant, FnField};
use polis::geom::{DVec2, Field};
use polis::roads::{
    Pattern, RoadClass, RoadInputs, RoadNetwork, RoadParams, generate, network_stats,
};

/// Writes `network` over a grey-scale rendering of population and water as SVG text.
fn svg(network: &RoadNetwork, params: &RoadParams, inputs: &RoadInputs) -> String {
    let (min, max) = (
        DVec2::from_array(params.bounds_min),
        DVec2::from_array(params.bounds_max),
    );
    let size = max - min;
    let scale = 1000.0 / size.x.max(size.y);
    let (w, h) = (size.x * scale, size.y * scale);
    let map = |p: DVec2| ((p.x - min.x) * scale, (max.y - p.y) * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.1} {h:.1}">"#
    );
    let _ = writeln!(
        s,
        r#"<rect width="100%" height="100%" fill="rgb(245,242,232)"/>"#
    );
    // Background: population (darker = denser), water in blue, parks in green.
    let n = 80;
    let (cw, ch) = (w / n as f64, h / n as f64);
    for j in 0..n {
        for i in 0..n {
            let p = DVec2::new(
                min.x + size.x * (i as f64 + 0.5) / n as f64,
                max.y - size.y * (j as f64 + 0.5) / n as f64,
            );
            let fill = if inputs.water.sample(p) >= 0.5 {
                "rgb(150,190,230)".to_string()
            } else if inputs.parks.sample(p) >= 0.5 {
                "rgb(170,210,160)".to_string()
            } else {
                let v = inputs.population.sample(p).clamp(0.0, 1.0);
                let g = (245.0 - 120.0 * v) as u8;
                format!("rgb({g},{g},{})", g.saturating_sub(10))
            };
            let _ = writeln!(
                s,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.2}" height="{:.2}" fill="{fill}"/>"#,
                i as f64 * cw,
                j as f64 * ch,
                cw + 0.3,
                ch + 0.3
            );
        }
    }
    for pass in [RoadClass::Street, RoadClass::Highway] {
        for (e, _, _, road) in network.edges() {
            if road.class != pass {
                continue;
            }
            let Ok((a, b)) = network.segment(e) else {
                continue;
            };
            let ((x1, y1), (x2, y2)) = (map(a), map(b));
            let (colour, width) = match (road.class, road.bridge) {
                (_, true) => ("rgb(200,40,40)", 3.0),
                (RoadClass::Highway, false) => ("rgb(230,140,20)", 2.6),
                (RoadClass::Street, false) => ("rgb(40,40,40)", 1.0),
            };
            let _ = writeln!(
                s,
                r#"<line x1="{x1:.2}" y1="{y1:.2}" x2="{x2:.2}" y2="{y2:.2}" stroke="{colour}" stroke-width="{width}" stroke-linecap="round"/>"#
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

fn run(
    name: &str,
    params: &RoadParams,
    inputs: &RoadInputs,
) -> Result<(), Box<dyn std::error::Error>> {
    let t = std::time::Instant::now();
    let city = generate(params, inputs)?;
    let dt = t.elapsed();
    city.network.check_invariants()?;
    let st = network_stats(&city.network);
    println!(
        "{name:<16} {:>6} segments {:>6} edges {:>5} steps  highways {:>7.0} m  streets {:>8.0} m  bridges {:>5.0} m  dead ends {:>4.1}%  {:>7.1} ms  ({:?})",
        city.report.segments,
        st.edges,
        city.report.steps,
        st.highway_length_m,
        st.street_length_m,
        st.bridge_length_m,
        100.0 * st.dead_ends as f64 / st.junctions.max(1) as f64,
        dt.as_secs_f64() * 1e3,
        city.report.stop,
    );
    std::fs::create_dir_all("out")?;
    std::fs::write(
        format!("out/roads_{name}.svg"),
        svg(&city.network, params, inputs),
    )?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let base = RoadParams {
        max_segments: 3000,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(base.seed, &base)?;
    for (name, pattern) in [
        ("basic", Pattern::Basic),
        ("new_york", Pattern::NewYork),
        ("paris", Pattern::Paris),
        ("san_francisco", Pattern::SanFrancisco),
    ] {
        let params = RoadParams {
            pattern,
            smooth_highways: pattern == Pattern::Basic,
            ..base.clone()
        };
        run(name, &params, &inputs)?;
    }

    // Fig. 7: New York in the west, Paris in the east, blended across the middle.
    let ramp = |p: DVec2| ((p.x + 600.0) / 1200.0).clamp(0.0, 1.0);
    let blended = inputs.clone().with_pattern_weights(vec![
        (
            Pattern::NewYork,
            Arc::new(FnField::new(move |p: DVec2| 1.0 - ramp(p))) as Arc<dyn Field>,
        ),
        (
            Pattern::Paris,
            Arc::new(FnField::new(ramp)) as Arc<dyn Field>,
        ),
    ]);
    let params = RoadParams {
        grid_angle_deg: 20.0,
        ..base.clone()
    };
    run("blend_ny_paris", &params, &blended)?;

    // A Manhattan-like island: a long island at 29°, a grid of 29°, water around it with
    // a second shore to the east (bridges), a coastal highway following the shore.
    let angle = 29f64.to_radians();
    let (c, s) = (angle.cos(), angle.sin());
    let island = move |p: DVec2| {
        let u = p.x * c + p.y * s; // along the island
        let v = -p.x * s + p.y * c; // across
        let width = 650.0 + 120.0 * (u / 400.0).sin();
        (u / 2600.0).powi(2) + (v / width).powi(2)
    };
    let water = FnField::new(move |p: DVec2| {
        let inside = island(p) <= 1.0;
        let v = -p.x * s + p.y * c;
        let mainland = !(-1000.0..=1050.0).contains(&v);
        if inside || mainland { 0.0 } else { 1.0 }
    });
    let population = FnField::new(move |p: DVec2| (1.0 - island(p)).clamp(0.0, 1.0) * 0.6 + 0.1);
    let manhattan = RoadInputs {
        population: Arc::new(population),
        water: Arc::new(water),
        parks: Arc::new(Constant(0.0)),
        elevation: Arc::new(Constant(0.0)),
        pattern_weights: Vec::new(),
        grid_angle: None,
    };
    let params = RoadParams {
        pattern: Pattern::NewYork,
        grid_angle_deg: 29.0,
        bounds_min: [-3000.0, -3000.0],
        bounds_max: [3000.0, 3000.0],
        start: Some([0.0, 0.0]),
        highway_branch_probability: 0.3,
        max_rotate_deg: 80.0,
        max_bridge_length_m: 450.0,
        max_segments: 4000,
        ..base
    };
    run("manhattan", &params, &manhattan)?;
    Ok(())
}
