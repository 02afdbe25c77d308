//! Adding a global goal without touching a production (Parish & Müller §3.1): highways
//! are pulled toward a landmark (a harbour, a castle) while everything else — streets,
//! patterns, branching — stays the default. Writes `out/roads_custom_goal.svg`.
//!
//! Run with `cargo run -p polis --release --example road_custom_goal`.

use std::fmt::Write as _;
use std::sync::Arc;

use polis::geom::DVec2;
use polis::lsystem::rand_pcg::Pcg64Mcg;
use polis::roads::{
    DefaultGoals, GlobalGoals, Proposal, RoadAttr, RoadClass, RoadGenerator, RoadInputs,
    RoadParams, RuleAttr,
};

/// The default goals, with highway continuations bent toward `landmark` by `pull`
/// (0 = default direction, 1 = straight at the landmark).
struct TowardLandmark {
    inner: DefaultGoals,
    landmark: DVec2,
    pull: f64,
}

impl GlobalGoals for TowardLandmark {
    fn axiom(&self) -> Vec<(RuleAttr, RoadAttr)> {
        self.inner.axiom()
    }

    fn successors(&self, rule: &RuleAttr, road: &RoadAttr, rng: &mut Pcg64Mcg) -> [Proposal; 3] {
        let mut out = self.inner.successors(rule, road, rng);
        let [cont, ..] = &mut out;
        let to = self.landmark - road.end;
        if rule.class == RoadClass::Highway && to.length() > cont.road.length {
            let ideal = DVec2::new(cont.road.angle.cos(), cont.road.angle.sin());
            let d = ideal * (1.0 - self.pull) + to.normalize() * self.pull;
            cont.road = RoadAttr::new(
                road.end,
                d.y.atan2(d.x),
                cont.road.length,
                RoadClass::Highway,
            );
        }
        out
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let params = RoadParams {
        max_segments: 2500,
        highway_branch_probability: 0.12,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params)?;
    let landmark = DVec2::new(-1700.0, 1600.0);
    let goals = TowardLandmark {
        inner: DefaultGoals::new(&params, &inputs)?,
        landmark,
        pull: 0.6,
    };
    let city = RoadGenerator::new(&params, &inputs)?
        .with_goals(Arc::new(goals))
        .run()?;
    city.network.check_invariants()?;
    let nearest = city
        .network
        .nodes()
        .map(|(_, p, _)| p.distance(landmark))
        .fold(f64::INFINITY, f64::min);
    println!(
        "{} segments; nearest junction to the landmark: {nearest:.0} m",
        city.report.segments
    );

    let mut svg = String::from(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="800" height="800" viewBox="-2000 -2000 4000 4000"><rect x="-2000" y="-2000" width="4000" height="4000" fill="rgb(245,242,232)"/>"#,
    );
    for (e, _, _, road) in city.network.edges() {
        let (a, b) = city.network.segment(e)?;
        let (c, w) = match road.class {
            RoadClass::Highway => ("rgb(230,140,20)", 14.0),
            RoadClass::Street => ("rgb(40,40,40)", 4.0),
        };
        let _ = write!(
            svg,
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{c}" stroke-width="{w}"/>"#,
            a.x, -a.y, b.x, -b.y
        );
    }
    let _ = write!(
        svg,
        r#"<circle cx="{}" cy="{}" r="40" fill="rgb(200,40,40)"/></svg>"#,
        landmark.x, -landmark.y
    );
    std::fs::create_dir_all("out")?;
    std::fs::write("out/roads_custom_goal.svg", svg)?;
    Ok(())
}
