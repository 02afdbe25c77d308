//! The main job: generate a whole city.
//!
//! The one-call pipeline (`polis::generate`) has not landed yet. Until it does, this
//! example runs what exists and says so honestly: it checks a few lot-sized polygons with
//! the polis-geom kernel and prints their measures.

use polis::geom::{DVec2, Polygon, PolygonWithHoles};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("polis: the full city pipeline is not implemented yet (see ARCHITECTURE.md).");
    println!("Running the geometry kernel on a few example blocks instead.\n");
    let block = Polygon::rect(DVec2::new(0.0, 0.0), DVec2::new(240.0, 60.0));
    let courtyard = {
        let mut h = Polygon::rect(DVec2::new(100.0, 20.0), DVec2::new(140.0, 40.0));
        h.make_cw();
        h
    };
    let with_yard = PolygonWithHoles::new(block.clone(), vec![courtyard]);
    with_yard.validate()?;
    println!(
        "{:<28} {:>10} {:>10} {:>20}",
        "shape", "area m²", "perimeter", "centroid"
    );
    for (name, p) in [
        ("Manhattan block 240×60", PolygonWithHoles::from(block)),
        ("block with courtyard", with_yard),
    ] {
        let c = p.centroid();
        println!(
            "{:<28} {:>10.1} {:>10.1} {:>20}",
            name,
            p.area(),
            p.perimeter(),
            format!("({:.1}, {:.1})", c.x, c.y)
        );
    }
    Ok(())
}
