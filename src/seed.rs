//! Sub-seeds: every stage and every item draws from its own seed, derived from the city
//! seed and a stable id, so changing one stage (or one cell) does not reshuffle the
//! random choices of the others, and parallel work needs no shared generator.

use polis_geom::hash::splitmix64 as splitmix;

/// Mixes `salt` into `seed`: `mix(s, a) != mix(s, b)` for `a != b`, and the result is
/// uncorrelated with both.
pub fn mix(seed: u64, salt: u64) -> u64 {
    splitmix(seed ^ splitmix(salt))
}

/// The seed of `stage` for the item with stable id `id` (a cell, a lot, a building).
pub fn sub_seed(city_seed: u64, stage: crate::Stage, id: u64) -> u64 {
    mix(mix(city_seed, 0x5EED_0000 + stage as u64), id)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Stage;

    #[test]
    fn sub_seeds_differ_by_stage_and_id() {
        let a = sub_seed(1, Stage::Lots, 7);
        assert_ne!(a, sub_seed(1, Stage::Lots, 8));
        assert_ne!(a, sub_seed(1, Stage::Buildings, 7));
        assert_ne!(a, sub_seed(2, Stage::Lots, 7));
        assert_eq!(a, sub_seed(1, Stage::Lots, 7));
    }
}
