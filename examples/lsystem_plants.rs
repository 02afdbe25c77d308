//! Draws figures of *The Algorithmic Beauty of Plants* (ch. 1) and the environmentally
//! sensitive pruning example of *Synthetic Topiary* with `polis-lsystem`, as SVG files in
//! `out/`.
//!
//! Run: `cargo run -p polis --example lsystem_plants` (add `--release` for speed).

use std::fmt::Write as _;
use std::time::Instant;

use polis::lsystem::glam::DVec3;
use polis::lsystem::{DeriveOptions, Geometry, Grammar, TurtleOptions};

struct Figure {
    name: &'static str,
    grammar: &'static str,
    steps: usize,
    angle: f64,
    seed: u64,
}

const FIGURES: &[Figure] = &[
    Figure {
        name: "abop_1_24a",
        grammar: "ω: F\nF -> F[+F]F[-F]F",
        steps: 5,
        angle: 25.7,
        seed: 0,
    },
    Figure {
        name: "abop_1_24b",
        grammar: "ω: F\nF -> F[+F]F[-F][F]",
        steps: 5,
        angle: 20.0,
        seed: 0,
    },
    Figure {
        name: "abop_1_24c",
        grammar: "ω: F\nF -> FF-[-F+F+F]+[+F-F-F]",
        steps: 4,
        angle: 22.5,
        seed: 0,
    },
    Figure {
        name: "abop_1_24d",
        grammar: "ω: X\nX -> F[+X]F[-X]+X\nF -> FF",
        steps: 7,
        angle: 20.0,
        seed: 0,
    },
    Figure {
        name: "abop_1_24e",
        grammar: "ω: X\nX -> F[+X][-X]FX\nF -> FF",
        steps: 7,
        angle: 25.7,
        seed: 0,
    },
    Figure {
        name: "abop_1_24f",
        grammar: "ω: X\nX -> F-[[X]+X]+F[+FX]-X\nF -> FF",
        steps: 5,
        angle: 22.5,
        seed: 0,
    },
    Figure {
        name: "koch_island",
        grammar: "ω: F-F-F-F\nF -> F-F+F+FF-F-F+F",
        steps: 3,
        angle: 90.0,
        seed: 0,
    },
    Figure {
        name: "koch_snowflake",
        grammar: "ω: F--F--F\nF -> F+F--F+F",
        steps: 4,
        angle: 60.0,
        seed: 0,
    },
    Figure {
        name: "stochastic_bush_seed1",
        grammar: "ω: F\nF -> F[+F]F[-F]F : 1\nF -> F[+F]F : 1\nF -> F[-F]F : 1",
        steps: 5,
        angle: 25.7,
        seed: 1,
    },
    Figure {
        name: "stochastic_bush_seed2",
        grammar: "ω: F\nF -> F[+F]F[-F]F : 1\nF -> F[+F]F : 1\nF -> F[-F]F : 1",
        steps: 5,
        angle: 25.7,
        seed: 2,
    },
    Figure {
        name: "stochastic_bush_seed3",
        grammar: "ω: F\nF -> F[+F]F[-F]F : 1\nF -> F[+F]F : 1\nF -> F[-F]F : 1",
        steps: 5,
        angle: 25.7,
        seed: 3,
    },
    Figure {
        name: "topiary_pruning",
        grammar: "
            ω: A
            p1: A -> [+B][-B]F?P(0,0)A
            p2: B -> F?P(0,0)@o(0.3)B
            p3: ?P(x,y) : 4*x^2 + (y-10)^2 > 10^2 -> [+(2*y)F][-(2*y)F]%
        ",
        steps: 30,
        angle: 45.0,
        seed: 0,
    },
    Figure {
        name: "abop_1_25_ternary_tree_3d",
        grammar: "
            #define d1 94.74
            #define d2 132.63
            #define a 18.95
            #define lr 1.109
            #define vr 1.732
            ω: !(1)F(200)/(45)A
            p1: A -> !(vr)F(50)[&(a)F(50)A]/(d1)[&(a)F(50)A]/(d2)[&(a)F(50)A]
            p2: F(l) -> F(l*lr)
            p3: !(w) -> !(w*vr)
        ",
        steps: 6,
        angle: 90.0,
        seed: 0,
    },
    Figure {
        name: "parametric_leafy_branch",
        grammar: "
            ω: '(1)A(1)
            A(s) : s < 6 -> F(s)[+(25)'(2)L]![-(25)A(s+1)]/(137.5)A(s+1)
            L -> {.-(30)f(2).+(60)f(2).+(120)f(2).+(60)f(2).}
        ",
        steps: 7,
        angle: 90.0,
        seed: 0,
    },
];

const PALETTE: &[&str] = &[
    "#3b2a1a", "#2f6b2f", "#5aa02c", "#8fcf3c", "#c0392b", "#1f618d",
];

/// Orthographic view onto the XY plane (the turtle grows along +Y).
fn svg(geo: &Geometry) -> String {
    let (lo, hi) = geo.bounds().unwrap_or((DVec3::ZERO, DVec3::ONE));
    let size = (hi - lo).max(DVec3::splat(1e-9));
    let scale = 760.0 / size.x.max(size.y);
    let (w, h) = (size.x * scale + 40.0, size.y * scale + 40.0);
    let px = |p: DVec3| ((p.x - lo.x) * scale + 20.0, (hi.y - p.y) * scale + 20.0);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.1} {h:.1}">"#
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for poly in &geo.polygons {
        let pts: Vec<String> = poly
            .vertices
            .iter()
            .map(|&p| {
                let (x, y) = px(p);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let colour = PALETTE[poly.colour as usize % PALETTE.len()];
        let _ = writeln!(
            out,
            r#"<polygon points="{}" fill="{colour}" stroke="none"/>"#,
            pts.join(" ")
        );
    }
    for line in geo.polylines() {
        let pts: Vec<String> = line
            .points
            .iter()
            .map(|&p| {
                let (x, y) = px(p);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let colour = PALETTE[line.colour as usize % PALETTE.len()];
        let width = (line.width * scale * 0.02).clamp(0.5, 12.0);
        let _ = writeln!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="{width:.2}" stroke-linecap="round"/>"#,
            pts.join(" ")
        );
    }
    for dot in &geo.dots {
        let (x, y) = px(dot.centre);
        let _ = writeln!(
            out,
            r##"<circle cx="{x:.2}" cy="{y:.2}" r="{:.2}" fill="#c0392b"/>"##,
            (dot.radius * scale).max(1.0)
        );
    }
    out.push_str("</svg>\n");
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all("out")?;
    println!(
        "{:<28} {:>5} {:>10} {:>9} {:>10}  file",
        "figure", "steps", "modules", "segments", "time ms"
    );
    for f in FIGURES {
        let t = Instant::now();
        let g = Grammar::parse(f.grammar)?;
        let mut d = g.derivation(DeriveOptions {
            seed: f.seed,
            turtle: TurtleOptions {
                angle_degrees: f.angle,
                width: 1.0,
                ..TurtleOptions::default()
            },
            ..DeriveOptions::default()
        });
        d.derive(f.steps)?;
        let mut geo = Geometry::default();
        d.interpret(&mut geo)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let path = format!("out/lsystem_{}.svg", f.name);
        std::fs::write(&path, svg(&geo))?;
        println!(
            "{:<28} {:>5} {:>10} {:>9} {:>10.2}  {path}",
            f.name,
            f.steps,
            d.string().len(),
            geo.segments.len(),
            ms
        );
    }
    Ok(())
}
