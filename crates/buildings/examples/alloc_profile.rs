//! Allocation profile of the building generator over the benchmark's 57,000 synthetic
//! lots: heap allocation calls per building, bytes allocated per building, heap bytes a
//! returned building keeps (and how many of them are spare capacity) at LOD 0, 1 and full
//! detail, and a digest of every output bit (to check that a change keeps the buildings
//! identical).
//!
//! Run: `cargo run --release -p polis-buildings --example alloc_profile`
//!
//! Allocation calls come from heaptrack (the workspace forbids the `unsafe` of a counting
//! global allocator): `heaptrack -o /tmp/b1 <example binary> 1` builds every lot once at
//! LOD 1 and keeps the buildings; `... lots` makes the lots only, the baseline to
//! subtract. Without arguments each LOD runs twice (warm, then timed) and the table
//! gives the capacity held per building, its unused part, and the digest.

use std::time::Instant;

use polis_buildings::{Building, BuildingGenerator, BuildingParams};

#[path = "../benches/common/lots.rs"]
mod city_lots;

/// FNV-1a over 64-bit words.
struct Digest(u64);

impl Digest {
    fn word(&mut self, w: u64) {
        for b in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3);
        }
    }

    fn f32s(&mut self, v: impl IntoIterator<Item = f32>) {
        for x in v {
            self.word(u64::from(x.to_bits()));
        }
    }

    fn building(&mut self, b: &Building) {
        self.word(b.id);
        self.word(b.lot_id);
        self.word(b.kind as u64);
        self.word(b.height.to_bits());
        self.word(u64::from(b.floors));
        self.word(b.lod as u64);
        self.word(b.origin.x.to_bits());
        self.word(b.origin.y.to_bits());
        self.word(u64::from(b.fallbacks));
        for p in b.footprint.points() {
            self.word(p.x.to_bits());
            self.word(p.y.to_bits());
        }
        for part in &b.parts {
            self.word(part.role as u64);
            let m = &part.mesh;
            self.f32s(m.positions.iter().flat_map(|p| p.to_array()));
            self.f32s(m.normals.iter().flat_map(|p| p.to_array()));
            self.f32s(m.uvs.iter().flat_map(|p| p.to_array()));
            for &i in &m.indices {
                self.word(u64::from(i));
            }
        }
        for f in &b.facades {
            for q in [f.origin, f.u, f.v] {
                for c in q.to_array() {
                    self.word(c.to_bits());
                }
            }
            self.word(f.width.to_bits());
            self.word(f.height.to_bits());
            self.word(u64::from(f.floors));
            self.word(f.role as u64);
            self.word(u64::from(f.part));
        }
    }
}

/// Heap bytes a building holds: (allocated capacity, of which unused).
fn held(b: &Building) -> (usize, usize) {
    fn v<T>(len: usize, cap: usize) -> (usize, usize) {
        let s = std::mem::size_of::<T>();
        (cap * s, (cap - len) * s)
    }
    let mut all = [
        v::<polis_buildings::Part>(b.parts.len(), b.parts.capacity()),
        v::<polis_buildings::FacadeFace>(b.facades.len(), b.facades.capacity()),
    ];
    // The footprint's capacity is not visible through `Polygon`; count its length.
    all[0].0 += std::mem::size_of_val(b.footprint.points());
    let mut total = (all[0].0 + all[1].0, all[0].1 + all[1].1);
    for p in &b.parts {
        let m = &p.mesh;
        for (c, s) in [
            v::<polis_geom::glam::Vec3>(m.positions.len(), m.positions.capacity()),
            v::<polis_geom::glam::Vec3>(m.normals.len(), m.normals.capacity()),
            v::<polis_geom::glam::Vec2>(m.uvs.len(), m.uvs.capacity()),
            v::<u32>(m.indices.len(), m.indices.capacity()),
        ] {
            total.0 += c;
            total.1 += s;
        }
    }
    total
}

fn main() {
    let g = BuildingGenerator::new(BuildingParams::default()).unwrap_or_else(|e| panic!("{e}"));
    let lots = city_lots::lots();
    let pass = |lod: usize| -> Vec<Building> {
        let mut keep = Vec::with_capacity(lots.len());
        for (i, (lot, kind)) in lots.iter().enumerate() {
            if let Ok(Some(b)) = g.build(lot, i as u64, *kind, 300.0, lod) {
                keep.push(b);
            }
        }
        keep
    };
    // Under heaptrack: `lots` makes the lots only (the baseline to subtract), a number
    // builds every lot once at that LOD and keeps the buildings to the end.
    match std::env::args().nth(1).as_deref() {
        Some("lots") => {
            println!("{} lots", lots.len());
            return;
        }
        Some(lod) => {
            let lod: usize = lod.parse().unwrap_or_else(|e| panic!("LOD {lod}: {e}"));
            let keep = pass(lod);
            println!("{} buildings at LOD {lod}", keep.len());
            return;
        }
        None => {}
    }
    println!(
        "{:<4} {:>6} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9}  digest",
        "LOD", "built", "held/bldg", "spare/b", "parts/b", "verts/b", "facades/b", "bldg/s"
    );
    for lod in [0usize, 1, 6] {
        drop(pass(lod));
        let start = Instant::now();
        let keep = pass(lod);
        let secs = start.elapsed().as_secs_f64();
        let n = keep.len().max(1) as f64;
        let mut d = Digest(0xCBF2_9CE4_8422_2325);
        let (mut cap, mut spare, mut parts, mut verts, mut faces) = (0, 0, 0, 0, 0);
        for b in &keep {
            d.building(b);
            let (c, s) = held(b);
            cap += c;
            spare += s;
            parts += b.parts.len();
            faces += b.facades.len();
            verts += b.parts.iter().map(|p| p.mesh.vertex_count()).sum::<usize>();
        }
        println!(
            "{lod:<4} {:>6} {:>10.0} {:>10.0} {:>8.2} {:>8.1} {:>9.2} {:>8.0}k  {:016x}",
            keep.len(),
            cap as f64 / n,
            spare as f64 / n,
            parts as f64 / n,
            verts as f64 / n,
            faces as f64 / n,
            n / secs / 1e3,
            d.0,
        );
    }
    println!(
        "(held/bldg: heap bytes of the returned Vecs' capacity per building; spare/b: of \
         which unused; a Building itself is {} bytes inline)",
        size_of::<Building>()
    );
}
