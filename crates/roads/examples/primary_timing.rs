//! Whole-process timing of the primary network's two benchmark operations, for
//! measurements from outside the process (`/usr/bin/time`, hyperfine):
//!
//! ```text
//! cargo run --release -p polis-roads --example primary_timing -- plot 20000
//! cargo run --release -p polis-roads --example primary_timing -- plot-lattice 20000
//! cargo run --release -p polis-roads --example primary_timing -- move 2000
//! ```
//!
//! The first argument picks the operation, the second how often to repeat it (0 = set-up
//! only: subtract that process's time and divide by the count to get one operation).
//! `plot` plots the 2 km road of `benches/primary.rs` (n_sample 7, d_sample 20 m,
//! even elevation difference) on raw fBm, `plot-lattice` on the lattice-cached fBm; `move`
//! proposes a move of the six-road node of the 500-road city (re-plot and validate).

#![allow(clippy::unwrap_used)]

use std::hint::black_box;

use polis_geom::DVec2;
use polis_roads::primary::{Edit, Strategy, plot};

#[path = "../benches/common/primary_city.rs"]
mod primary_city;
use primary_city::{ROAD_2KM, city, params, terrain, terrain_lattice};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let what = args.get(1).map_or("plot", String::as_str);
    let n: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let mut check = 0usize;
    match what {
        "plot" | "plot-lattice" => {
            let t = if what == "plot" {
                terrain()
            } else {
                terrain_lattice()
            };
            let p = params(Strategy::EvenElevationDifference);
            let (a, b) = ROAD_2KM;
            for _ in 0..n {
                check += plot(black_box(a), black_box(b), &p, &t)
                    .unwrap()
                    .points
                    .len();
            }
        }
        "move" => {
            let (ed, c) = city();
            let home = ed.network().node(c).unwrap().pos;
            for k in 0..n {
                let to = home + DVec2::from_angle(f64::from(k % 8) * 0.785) * 12.0;
                check += ed
                    .propose(&Edit::MoveNode { node: c, to })
                    .unwrap()
                    .roads()
                    .len();
            }
        }
        other => {
            eprintln!("unknown operation {other:?}: use plot, plot-lattice or move");
            std::process::exit(2);
        }
    }
    println!("{what} x{n}: checksum {check}");
}
