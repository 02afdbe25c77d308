//! What [`City::write_all`](crate::City::write_all) writes: the set of file formats and
//! the GeoJSON's geographic anchor.

use std::fmt;
use std::str::FromStr;

#[cfg(feature = "gltf")]
use polis_export::glb::GlbProfile;
use serde::{Deserialize, Serialize};

/// The output formats to write. `"glb,obj,svg,geojson"` parses into all four
/// ([`FromStr`]), and [`Display`](fmt::Display) writes the same list back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Formats {
    /// `city.glb`: glTF 2.0 binary, textures embedded. Default: true.
    pub glb: bool,
    /// `city.obj` + `city.mtl` + `textures/*.png`. Default: true.
    pub obj: bool,
    /// `city.svg`: the 2-D map. Default: true.
    pub svg: bool,
    /// `city.geojson`: the map layers as RFC 7946 features. Default: true.
    pub geojson: bool,
}

impl Formats {
    /// Every format.
    pub const ALL: Formats = Formats {
        glb: true,
        obj: true,
        svg: true,
        geojson: true,
    };
    /// No format (nothing is written).
    pub const NONE: Formats = Formats {
        glb: false,
        obj: false,
        svg: false,
        geojson: false,
    };
    /// The formats this build can write: each needs the polis-city feature of its name
    /// (`gltf` for glb), all on by default.
    pub const AVAILABLE: Formats = Formats {
        glb: cfg!(feature = "gltf"),
        obj: cfg!(feature = "obj"),
        svg: cfg!(feature = "svg"),
        geojson: cfg!(feature = "geojson"),
    };
    /// The format names, in the order [`Display`](fmt::Display) lists them.
    pub const NAMES: [&'static str; 4] = ["glb", "obj", "svg", "geojson"];
    /// The cargo feature of polis-city each format needs, in [`NAMES`](Self::NAMES) order.
    pub const FEATURES: [&'static str; 4] = ["gltf", "obj", "svg", "geojson"];

    /// The first format asked for that this build cannot write, with the feature it
    /// needs; `None` when every one asked for is [`AVAILABLE`](Self::AVAILABLE).
    pub fn not_compiled(self) -> Option<(&'static str, &'static str)> {
        (0..4)
            .find(|&i| self.flags()[i] && !Formats::AVAILABLE.flags()[i])
            .map(|i| (Formats::NAMES[i], Formats::FEATURES[i]))
    }

    fn flags(self) -> [bool; 4] {
        [self.glb, self.obj, self.svg, self.geojson]
    }
}

impl Default for Formats {
    /// [`Formats::AVAILABLE`]: all four with the default features.
    fn default() -> Self {
        Formats::AVAILABLE
    }
}

impl fmt::Display for Formats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = Formats::NAMES
            .iter()
            .zip(self.flags())
            .filter_map(|(n, on)| on.then_some(*n))
            .collect();
        f.write_str(&names.join(","))
    }
}

/// A format list that names an unknown format.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown output format {0:?}; give a comma-separated list of glb, obj, svg, geojson")]
pub struct UnknownFormat(pub String);

impl FromStr for Formats {
    type Err = UnknownFormat;

    /// A comma-separated list of `glb`, `obj`, `svg`, `geojson` (case-insensitive,
    /// spaces ignored, repeats allowed); `all` for every format this build can write
    /// ([`Formats::AVAILABLE`]).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut out = Formats::NONE;
        for part in s.split(',').map(str::trim) {
            match part.to_ascii_lowercase().as_str() {
                "glb" => out.glb = true,
                "obj" => out.obj = true,
                "svg" => out.svg = true,
                "geojson" => out.geojson = true,
                "all" => out = Formats::AVAILABLE,
                _ => return Err(UnknownFormat(part.to_string())),
            }
        }
        Ok(out)
    }
}

/// How [`City::write_all_with`](crate::City::write_all_with) writes.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct WriteOptions {
    /// Which files to write. Default: [`Formats::AVAILABLE`] (all four with the default
    /// features).
    pub formats: Formats,
    /// `[longitude, latitude]` (degrees, WGS 84) of the layout origin: with it the
    /// GeoJSON holds RFC 7946 longitude/latitude (a local tangent-plane projection; see
    /// `polis_export::geojson::projection` for its error), without it local metres.
    /// Default: none.
    pub anchor_lon_lat: Option<[f64; 2]>,
    /// Extensions the glb may use: plain glTF 2.0, or the web profile (quantized,
    /// meshopt-compressed). Default: [`GlbProfile::Plain`]. Only with the feature `gltf`.
    #[cfg(feature = "gltf")]
    pub glb_profile: GlbProfile,
    /// The SVG's debug overlays (Kelly's debug views: plot samples and fans, block and lot
    /// boundaries, lot split lines). Default: none. Only with the feature `svg`.
    #[cfg(feature = "svg")]
    pub svg_debug: polis_export::svg::SvgDebug,
}

impl From<Formats> for WriteOptions {
    fn from(formats: Formats) -> Self {
        WriteOptions {
            formats,
            anchor_lon_lat: None,
            #[cfg(feature = "gltf")]
            glb_profile: GlbProfile::Plain,
            #[cfg(feature = "svg")]
            svg_debug: polis_export::svg::SvgDebug::default(),
        }
    }
}

/// The subfolder of the output folder that holds the OBJ's texture PNGs.
pub const TEXTURE_DIR: &str = "textures";

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn parses_lists_and_refuses_unknown_names() {
        assert_eq!("glb,obj,svg,geojson".parse::<Formats>(), Ok(Formats::ALL));
        assert_eq!("all".parse::<Formats>(), Ok(Formats::AVAILABLE));
        let only = " SVG , glb,glb".parse::<Formats>().unwrap();
        assert_eq!(
            only,
            Formats {
                glb: true,
                svg: true,
                ..Formats::NONE
            }
        );
        assert_eq!(only.to_string(), "glb,svg");
        assert!("glb,gltf".parse::<Formats>().is_err());
        assert!("".parse::<Formats>().is_err());
    }

    proptest! {
        /// Display and FromStr round-trip every non-empty set.
        #[test]
        fn display_round_trips(bits in 1u8..16) {
            let f = Formats {
                glb: bits & 1 != 0,
                obj: bits & 2 != 0,
                svg: bits & 4 != 0,
                geojson: bits & 8 != 0,
            };
            prop_assert_eq!(f.to_string().parse::<Formats>(), Ok(f));
        }
    }
}
