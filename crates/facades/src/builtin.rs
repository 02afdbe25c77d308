//! Built-in styles: brick house, office glass curtain wall, classic stone with cornices and
//! a distinct ground floor, industrial shed.
//!
//! Each is plain data (serialise one with serde to start a style of your own). Sizes are
//! typical measured values: storeys 2.8–3.6 m, sash windows 1.1 × 1.45 m, curtain-wall
//! modules 1.5 m, stone blocks 0.9 × 0.45 m.

use crate::axis::{AxisStyle, Segment};
use crate::color::{Bricks, Col};
use crate::facade::FacadeStyle;
use crate::image::ImageStyle;
use crate::layer::CellRole;
use crate::profile::Profile;
use crate::sample::FacadeSample;
use crate::stack::Relation;
use crate::style::{AxisRef, EvalStyle, InfluenceStyle, LayerStyle, Pick, Select, StackStyle};
use crate::tiles::TileOptions;

const fn rgb(r: f32, g: f32, b: f32) -> FacadeSample {
    FacadeSample::rgb(r, g, b)
}

fn whole(mut l: LayerStyle) -> LayerStyle {
    l.u = AxisRef::Whole;
    l.v = AxisRef::Whole;
    l
}

fn band(name: &str, rows: &[&str], role: CellRole, col: Col, depth_m: f32) -> LayerStyle {
    LayerStyle {
        u: AxisRef::Whole,
        rows: Select::named(rows),
        depth_m,
        ..LayerStyle::new(name, role, EvalStyle::Always, col)
    }
}

fn bricks(
    brick: FacadeSample,
    mortar: FacadeSample,
    size_m: [f64; 2],
    joint_m: f64,
    bond: f64,
    variation: f32,
) -> Col {
    Col::Bricks(Bricks {
        brick,
        mortar,
        size_m,
        joint_m,
        bond,
        variation,
        in_cell: false,
        salt: 0,
    })
}

fn sash(panes: [u32; 2], open: f32, curtain: Option<[f32; 3]>) -> ImageStyle {
    ImageStyle::SashWindow {
        panes,
        open,
        frame: rgb(0.92, 0.91, 0.87).with_pbr(0.5, 0.0),
        glass_low: rgb(0.13, 0.16, 0.2).with_pbr(0.05, 0.0),
        glass_high: rgb(0.42, 0.52, 0.62).with_pbr(0.05, 0.0),
        interior: rgb(0.05, 0.045, 0.04).with_height(-0.25),
        curtain,
    }
}

fn scale(source: &str, target: &str, relation: Relation, scale: [f64; 2]) -> InfluenceStyle {
    InfluenceStyle::ScaleCells {
        source: source.into(),
        target: target.into(),
        relation,
        scale,
    }
}

fn border(source: &str, target: &str, margin_m: f64, col: Col) -> InfluenceStyle {
    InfluenceStyle::Border {
        source: source.into(),
        target: target.into(),
        margin_m,
        col,
    }
}

/// Every built-in style.
pub fn builtin_styles() -> Vec<FacadeStyle> {
    vec![
        brick_house(),
        office_curtain_wall(),
        classic_stone(),
        industrial(),
    ]
}

/// A built-in style by name (`brick_house`, `office_curtain_wall`, `classic_stone`,
/// `industrial`).
pub fn builtin_style(name: &str) -> Option<FacadeStyle> {
    builtin_styles().into_iter().find(|s| s.name == name)
}

/// A terraced brick house: running-bond brick, dark plinth, sash windows chosen at random
/// per cell (closed, half open, open, curtained), stone sills, a soldier course around
/// every opening (an inter-layer border), a door in the middle bay that removes the window
/// it overlaps and shrinks the one above it (inter-layer scaling), painted eaves.
pub fn brick_house() -> FacadeStyle {
    let mortar = rgb(0.7, 0.68, 0.63).with_height(-0.008).with_pbr(0.95, 0.0);
    let window_rows = Profile::At {
        offset_m: 0.85,
        size_m: 1.45,
    };
    let columns = AxisStyle {
        start: vec![Segment::flexible("margin", 0.9, Profile::Off).with_min(0.4)],
        module: vec![
            Segment::flexible("pier", 0.55, Profile::Off).with_min(0.25),
            Segment::rigid("window", 1.1, Profile::Full),
            Segment::flexible("pier", 0.55, Profile::Off).with_min(0.25),
        ],
        end: vec![Segment::flexible("margin", 0.9, Profile::Off).with_min(0.4)],
        min_repeats: 1,
        max_repeats: None,
    };
    let rows = AxisStyle {
        start: vec![
            Segment::rigid("plinth", 0.45, Profile::Off),
            Segment::flexible("ground", 2.9, window_rows)
                .storey()
                .with_min(2.4),
        ],
        module: vec![
            Segment::flexible("floor", 2.8, window_rows)
                .storey()
                .with_min(2.4),
        ],
        end: vec![Segment::rigid("eaves", 0.5, Profile::Off)],
        min_repeats: 0,
        max_repeats: None,
    };
    let wall = whole(LayerStyle::new(
        "wall",
        CellRole::Wall,
        EvalStyle::Always,
        bricks(
            rgb(0.56, 0.24, 0.17),
            mortar,
            [0.225, 0.075],
            0.01,
            0.5,
            0.12,
        ),
    ));
    let plinth = band(
        "plinth",
        &["plinth"],
        CellRole::Plinth,
        bricks(
            rgb(0.3, 0.15, 0.12),
            mortar,
            [0.225, 0.075],
            0.01,
            0.5,
            0.08,
        ),
        0.02,
    );
    let eaves = band(
        "eaves",
        &["eaves"],
        CellRole::Cornice,
        Col::Solid(rgb(0.88, 0.86, 0.8).with_pbr(0.6, 0.0)),
        0.06,
    );
    let sills = LayerStyle {
        cols: Select::named(&["window"]),
        rows: Select::named(&["ground", "floor"]),
        v_profile: Some(Profile::At {
            offset_m: 0.77,
            size_m: 0.08,
        }),
        depth_m: 0.04,
        ..LayerStyle::new(
            "sills",
            CellRole::Ledge,
            EvalStyle::And,
            Col::Solid(rgb(0.8, 0.78, 0.72)),
        )
    };
    let windows = LayerStyle {
        cols: Select::named(&["window"]),
        rows: Select::named(&["ground", "floor"]),
        depth_m: -0.1,
        ..LayerStyle::new(
            "windows",
            CellRole::Window,
            EvalStyle::Image {
                images: vec![
                    sash([2, 2], 0.0, None),
                    sash([2, 2], 0.5, None),
                    sash([2, 2], 1.0, None),
                    sash([2, 2], 0.0, Some([0.75, 0.7, 0.55])),
                ],
                weights: vec![4.0, 2.0, 1.0, 2.0],
            },
            Col::Inherit {
                fallback: rgb(0.2, 0.2, 0.2),
            },
        )
    };
    let door = LayerStyle {
        cols: Select::named(&["window"]).pick(Pick::Middle),
        rows: Select::named(&["ground"]),
        v_profile: Some(Profile::At {
            offset_m: 0.0,
            size_m: 2.3,
        }),
        depth_m: -0.08,
        street_only: true,
        ..LayerStyle::new(
            "door",
            CellRole::Door,
            EvalStyle::And,
            Col::Frame {
                inner: rgb(0.1, 0.26, 0.19).with_pbr(0.4, 0.0),
                edge: rgb(0.92, 0.91, 0.87),
                width_m: 0.07,
            },
        )
    };
    let soldier = bricks(
        rgb(0.42, 0.17, 0.12),
        mortar,
        [0.075, 0.225],
        0.01,
        0.0,
        0.1,
    );
    FacadeStyle {
        name: "brick_house".into(),
        columns,
        rows,
        stack: StackStyle {
            layers: vec![wall, plinth, eaves, sills, windows, door],
            influences: vec![
                scale("door", "windows", Relation::Overlap, [0.0, 0.0]),
                scale(
                    "door",
                    "windows",
                    Relation::Above { max_gap_m: 2.5 },
                    [1.0, 0.55],
                ),
                border("windows", "wall", 0.1, soldier.clone()),
                border("door", "wall", 0.1, soldier),
            ],
            background: None,
        },
        tiles: TileOptions::default(),
        tint_jitter: 0.08,
    }
}

/// An office tower clad in a glass curtain wall: aluminium mullions and transoms, dark
/// spandrel panels at slab level, vision glass with blinds at random heights per cell, a
/// tall glazed lobby with a central entrance, an aluminium parapet.
pub fn office_curtain_wall() -> FacadeStyle {
    let alu = rgb(0.56, 0.58, 0.61).with_pbr(0.35, 0.9);
    let glass = rgb(0.2, 0.3, 0.38).with_pbr(0.04, 0.2);
    let columns = AxisStyle {
        start: vec![Segment::rigid("edge", 0.35, Profile::Off)],
        module: vec![
            Segment::rigid("mullion", 0.08, Profile::Off),
            Segment::flexible("panel", 1.42, Profile::Full).with_min(0.9),
        ],
        end: vec![
            Segment::rigid("mullion", 0.08, Profile::Off),
            Segment::rigid("edge", 0.35, Profile::Off),
        ],
        min_repeats: 1,
        max_repeats: None,
    };
    let rows = AxisStyle {
        start: vec![
            Segment::flexible("lobby", 4.8, Profile::Off)
                .storey()
                .with_min(3.6),
        ],
        module: vec![
            Segment::flexible("floor", 3.6, Profile::Off)
                .storey()
                .with_min(3.0),
        ],
        end: vec![Segment::rigid("parapet", 1.2, Profile::Off)],
        min_repeats: 0,
        max_repeats: None,
    };
    let on_panels = |name: &str, rows: &[&str], v: Profile, role, eval, col, depth_m| LayerStyle {
        cols: Select::named(&["panel"]),
        rows: Select::named(rows),
        v_profile: Some(v),
        depth_m,
        ..LayerStyle::new(name, role, eval, col)
    };
    let blinds = |lowered: f32| ImageStyle::Blinds {
        glass,
        blind: rgb(0.78, 0.77, 0.72).with_pbr(0.7, 0.0),
        lowered,
    };
    let layers = vec![
        whole(LayerStyle::new(
            "frame",
            CellRole::Pier,
            EvalStyle::Always,
            Col::Solid(alu),
        )),
        on_panels(
            "spandrel",
            &["floor"],
            Profile::At {
                offset_m: 0.06,
                size_m: 0.94,
            },
            CellRole::Panel,
            EvalStyle::And,
            Col::Solid(rgb(0.1, 0.12, 0.15).with_pbr(0.08, 0.3)),
            -0.02,
        ),
        on_panels(
            "vision",
            &["floor"],
            Profile::Inset {
                start_m: 1.08,
                end_m: 0.06,
            },
            CellRole::Glass,
            EvalStyle::Image {
                images: vec![blinds(0.0), blinds(0.15), blinds(0.4), blinds(0.85)],
                weights: vec![3.0, 2.0, 2.0, 1.0],
            },
            Col::Inherit { fallback: glass },
            -0.03,
        ),
        on_panels(
            "lobby",
            &["lobby"],
            Profile::Inset {
                start_m: 0.12,
                end_m: 0.45,
            },
            CellRole::Shopfront,
            EvalStyle::And,
            Col::Gradient {
                bottom: rgb(0.08, 0.1, 0.12).with_pbr(0.04, 0.2),
                top: rgb(0.3, 0.4, 0.48).with_pbr(0.04, 0.2),
            },
            -0.05,
        ),
        LayerStyle {
            street_only: true,
            cols: Select::named(&["panel"]).pick(Pick::Middle),
            ..on_panels(
                "entrance",
                &["lobby"],
                Profile::At {
                    offset_m: 0.12,
                    size_m: 2.7,
                },
                CellRole::Door,
                EvalStyle::And,
                Col::Frame {
                    inner: rgb(0.05, 0.06, 0.07).with_pbr(0.05, 0.1),
                    edge: rgb(0.3, 0.31, 0.33).with_pbr(0.3, 0.9),
                    width_m: 0.08,
                },
                -0.3,
            )
        },
        band(
            "parapet",
            &["parapet"],
            CellRole::Cornice,
            Col::Solid(rgb(0.66, 0.68, 0.7).with_pbr(0.3, 0.9)),
            0.05,
        ),
    ];
    FacadeStyle {
        name: "office_curtain_wall".into(),
        columns,
        rows,
        stack: StackStyle {
            layers,
            influences: vec![],
            background: None,
        },
        tiles: TileOptions { bays: 4, floors: 2 },
        tint_jitter: 0.05,
    }
}

/// A classic stone building: ashlar walls, a rusticated ground floor with its own rhythm
/// of tall openings, quoins, string courses (an OR layer), a dentilled cornice and attic,
/// upper windows as nested layers (frame + glazing bars that adapt to the window), a
/// central door that removes the ground opening it hits and enlarges the window above it.
pub fn classic_stone() -> FacadeStyle {
    let stone = rgb(0.8, 0.75, 0.66).with_pbr(0.85, 0.0);
    let joint = rgb(0.66, 0.62, 0.55).with_height(-0.012);
    let columns = AxisStyle {
        start: vec![Segment::rigid("quoin", 0.9, Profile::Off)],
        module: vec![
            Segment::flexible("pier", 0.75, Profile::Off).with_min(0.4),
            Segment::rigid("window", 1.3, Profile::Full),
            Segment::flexible("pier", 0.75, Profile::Off).with_min(0.4),
        ],
        end: vec![Segment::rigid("quoin", 0.9, Profile::Off)],
        min_repeats: 1,
        max_repeats: None,
    };
    let window_rows = Profile::At {
        offset_m: 0.9,
        size_m: 2.0,
    };
    let rows = AxisStyle {
        start: vec![
            Segment::rigid("plinth", 0.7, Profile::Off),
            Segment::flexible("ground", 4.4, Profile::Off)
                .storey()
                .with_min(3.7),
        ],
        module: vec![
            Segment::flexible("floor", 3.5, window_rows)
                .storey()
                .with_min(3.1),
        ],
        end: vec![
            Segment::rigid("cornice", 0.9, Profile::Full),
            Segment::flexible("attic", 1.2, Profile::Off).with_min(0.6),
        ],
        min_repeats: 0,
        max_repeats: None,
    };
    // The nested window: a white frame with glazing bars fitted to the opening.
    let bars = |pane: f64| AxisStyle {
        start: vec![Segment::rigid("frame", 0.07, Profile::Off)],
        module: vec![
            Segment::flexible("pane", pane, Profile::Full).with_min(0.15),
            Segment::rigid("bar", 0.04, Profile::Off),
        ],
        end: vec![Segment::rigid("frame", 0.03, Profile::Off)],
        min_repeats: 1,
        max_repeats: None,
    };
    let nested_window = StackStyle {
        layers: vec![
            whole(LayerStyle::new(
                "frame",
                CellRole::Frame,
                EvalStyle::Always,
                Col::Solid(rgb(0.93, 0.92, 0.88).with_pbr(0.5, 0.0)),
            )),
            LayerStyle {
                u: AxisRef::Own(bars(0.45)),
                v: AxisRef::Own(bars(0.5)),
                depth_m: -0.03,
                ..LayerStyle::new(
                    "panes",
                    CellRole::Glass,
                    EvalStyle::And,
                    Col::Gradient {
                        bottom: rgb(0.12, 0.15, 0.19).with_pbr(0.05, 0.0),
                        top: rgb(0.45, 0.55, 0.64).with_pbr(0.05, 0.0),
                    },
                )
            },
        ],
        influences: vec![],
        background: None,
    };
    let layers = vec![
        whole(LayerStyle::new(
            "ashlar",
            CellRole::Wall,
            EvalStyle::Always,
            bricks(stone, joint, [0.9, 0.45], 0.012, 0.5, 0.05),
        )),
        band(
            "rustication",
            &["plinth", "ground"],
            CellRole::Plinth,
            bricks(
                stone.shade(0.93),
                joint.with_height(-0.035),
                [1.2, 0.5],
                0.045,
                0.0,
                0.04,
            ),
            0.03,
        ),
        LayerStyle {
            cols: Select::named(&["quoin"]),
            rows: Select::named(&["floor"]),
            depth_m: 0.03,
            ..LayerStyle::new(
                "quoins",
                CellRole::Pier,
                EvalStyle::Always,
                // Long and short blocks alternating course by course.
                Col::Bricks(Bricks {
                    brick: stone.shade(1.12),
                    mortar: joint.with_height(-0.03),
                    size_m: [1.2, 0.45],
                    joint_m: 0.035,
                    bond: 0.5,
                    variation: 0.03,
                    in_cell: true,
                    salt: 1,
                }),
            )
        },
        LayerStyle {
            u_profile: Some(Profile::Off),
            rows: Select::named(&["floor"]),
            v_profile: Some(Profile::At {
                offset_m: 0.0,
                size_m: 0.22,
            }),
            depth_m: 0.06,
            ..LayerStyle::new(
                "string_course",
                CellRole::Ledge,
                EvalStyle::Or,
                Col::Solid(stone.shade(1.06)),
            )
        },
        LayerStyle {
            u: AxisRef::Whole,
            rows: Select::named(&["cornice"]),
            depth_m: 0.25,
            ..LayerStyle::new(
                "cornice",
                CellRole::Cornice,
                EvalStyle::Always,
                Col::Bricks(Bricks {
                    brick: stone.shade(1.08),
                    mortar: stone.shade(0.55).with_height(-0.06),
                    size_m: [0.3, 0.3],
                    joint_m: 0.1,
                    bond: 0.0,
                    variation: 0.0,
                    in_cell: true,
                    salt: 0,
                }),
            )
        },
        LayerStyle {
            cols: Select::named(&["window"]),
            rows: Select::named(&["floor"]),
            v_profile: Some(Profile::At {
                offset_m: 0.75,
                size_m: 2.35,
            }),
            depth_m: 0.04,
            ..LayerStyle::new(
                "surrounds",
                CellRole::Ornament,
                EvalStyle::And,
                Col::Solid(stone.shade(1.1)),
            )
        },
        LayerStyle {
            cols: Select::named(&["window"]),
            rows: Select::named(&["floor"]),
            u_profile: Some(Profile::Centered { size_m: 1.06 }),
            depth_m: -0.15,
            ..LayerStyle::new(
                "windows",
                CellRole::Window,
                EvalStyle::Nested(Box::new(nested_window)),
                Col::Inherit { fallback: stone },
            )
        },
        LayerStyle {
            u: AxisRef::Own(AxisStyle {
                start: vec![Segment::flexible("end", 0.6, Profile::Off).with_min(0.3)],
                module: vec![
                    Segment::flexible("pier", 0.9, Profile::Off).with_min(0.5),
                    Segment::rigid("opening", 2.0, Profile::Full),
                    Segment::flexible("pier", 0.9, Profile::Off).with_min(0.5),
                ],
                end: vec![Segment::flexible("end", 0.6, Profile::Off).with_min(0.3)],
                min_repeats: 1,
                max_repeats: None,
            }),
            cols: Select::named(&["opening"]),
            rows: Select::named(&["ground"]),
            v_profile: Some(Profile::At {
                offset_m: 0.3,
                size_m: 3.3,
            }),
            depth_m: -0.2,
            ..LayerStyle::new(
                "ground_openings",
                CellRole::Shopfront,
                EvalStyle::Image {
                    images: vec![
                        sash([3, 3], 0.0, None),
                        sash([3, 3], 0.6, None),
                        sash([3, 3], 0.0, Some([0.55, 0.12, 0.1])),
                    ],
                    weights: vec![3.0, 1.0, 1.0],
                },
                Col::Inherit { fallback: stone },
            )
        },
        LayerStyle {
            cols: Select::named(&["window"]).pick(Pick::Middle),
            rows: Select::named(&["ground"]),
            u_profile: Some(Profile::Centered { size_m: 1.7 }),
            v_profile: Some(Profile::At {
                offset_m: 0.0,
                size_m: 3.5,
            }),
            depth_m: -0.3,
            street_only: true,
            ..LayerStyle::new(
                "door",
                CellRole::Door,
                EvalStyle::And,
                Col::Frame {
                    inner: rgb(0.28, 0.16, 0.09).with_pbr(0.5, 0.0),
                    edge: rgb(0.2, 0.12, 0.07).with_pbr(0.5, 0.0),
                    width_m: 0.1,
                },
            )
        },
    ];
    FacadeStyle {
        name: "classic_stone".into(),
        columns,
        rows,
        stack: StackStyle {
            layers,
            influences: vec![
                scale(
                    "door",
                    "ground_openings",
                    Relation::Near { distance_m: 0.3 },
                    [0.0, 0.0],
                ),
                scale(
                    "door",
                    "windows",
                    Relation::Above { max_gap_m: 2.0 },
                    [1.0, 1.12],
                ),
                border(
                    "door",
                    "rustication",
                    0.3,
                    bricks(
                        stone.shade(1.08),
                        joint.with_height(-0.035),
                        [0.3, 0.5],
                        0.04,
                        0.5,
                        0.03,
                    ),
                ),
            ],
            background: None,
        },
        tiles: TileOptions::default(),
        tint_jitter: 0.06,
    }
}

/// An industrial shed: corrugated steel cladding, a concrete-block dado, steel columns at
/// every bay (an OR layer), a ribbon of factory glazing under the eaves, a roller-shutter
/// loading door in the middle bay (on its own axis: left out on faces lower than 4.7 m)
/// that removes the glazing above it, edged in safety yellow.
pub fn industrial() -> FacadeStyle {
    let steel = rgb(0.47, 0.52, 0.55).with_pbr(0.45, 0.7);
    let columns = AxisStyle {
        start: vec![Segment::rigid("edge", 0.4, Profile::Off)],
        module: vec![
            Segment::flexible("bay", 6.0, Profile::Centered { size_m: 4.2 }).with_min(4.5),
        ],
        end: vec![Segment::rigid("edge", 0.4, Profile::Off)],
        min_repeats: 1,
        max_repeats: None,
    };
    let rows = AxisStyle {
        start: vec![Segment::rigid("dado", 1.5, Profile::Off)],
        module: vec![Segment::flexible("band", 2.5, Profile::Off).with_min(1.8)],
        end: vec![Segment::rigid("eaves", 0.5, Profile::Off)],
        min_repeats: 1,
        max_repeats: None,
    };
    let layers = vec![
        whole(LayerStyle::new(
            "cladding",
            CellRole::Wall,
            EvalStyle::Always,
            Col::Corrugated {
                base: steel,
                period_m: 0.2,
                depth_m: 0.035,
                vertical: true,
            },
        )),
        band(
            "dado",
            &["dado"],
            CellRole::Plinth,
            bricks(
                rgb(0.62, 0.62, 0.6).with_pbr(0.9, 0.0),
                rgb(0.52, 0.52, 0.5).with_height(-0.006),
                [0.44, 0.215],
                0.01,
                0.5,
                0.05,
            ),
            0.02,
        ),
        LayerStyle {
            cols: Select::named(&["bay"]),
            u_profile: Some(Profile::At {
                offset_m: 0.0,
                size_m: 0.25,
            }),
            v_profile: Some(Profile::Off),
            depth_m: 0.06,
            ..LayerStyle::new(
                "steel_columns",
                CellRole::Pier,
                EvalStyle::Or,
                Col::Solid(rgb(0.2, 0.26, 0.32).with_pbr(0.5, 0.6)),
            )
        },
        LayerStyle {
            cols: Select::named(&["bay"]),
            rows: Select::named(&["band"]).pick(Pick::Index { index: -1 }),
            v_profile: Some(Profile::Inset {
                start_m: 0.5,
                end_m: 0.5,
            }),
            depth_m: -0.05,
            ..LayerStyle::new(
                "glazing",
                CellRole::Window,
                EvalStyle::Image {
                    images: vec![sash([6, 2], 0.0, None), sash([6, 2], 0.3, None)],
                    weights: vec![4.0, 1.0],
                },
                Col::Inherit { fallback: steel },
            )
        },
        LayerStyle {
            cols: Select::named(&["bay"]).pick(Pick::Middle),
            u_profile: Some(Profile::Centered { size_m: 3.6 }),
            v: AxisRef::Own(AxisStyle {
                start: vec![Segment::rigid("door", 4.2, Profile::Full)],
                end: vec![Segment::flexible("above", 0.5, Profile::Off).with_min(0.5)],
                ..AxisStyle::default()
            }),
            depth_m: -0.1,
            street_only: true,
            ..LayerStyle::new(
                "loading_door",
                CellRole::Door,
                EvalStyle::And,
                Col::Corrugated {
                    base: rgb(0.62, 0.64, 0.65).with_pbr(0.4, 0.8),
                    period_m: 0.1,
                    depth_m: 0.015,
                    vertical: false,
                },
            )
        },
        band(
            "eaves",
            &["eaves"],
            CellRole::Cornice,
            Col::Solid(rgb(0.24, 0.26, 0.29).with_pbr(0.5, 0.6)),
            0.08,
        ),
    ];
    FacadeStyle {
        name: "industrial".into(),
        columns,
        rows,
        stack: StackStyle {
            layers,
            influences: vec![
                scale(
                    "loading_door",
                    "glazing",
                    Relation::Above { max_gap_m: 3.0 },
                    [0.0, 0.0],
                ),
                border(
                    "loading_door",
                    "cladding",
                    0.15,
                    Col::Solid(rgb(0.9, 0.72, 0.08).with_pbr(0.6, 0.0)),
                ),
            ],
            background: None,
        },
        tiles: TileOptions { bays: 2, floors: 1 },
        tint_jitter: 0.1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_validate_and_have_unique_names() {
        let styles = builtin_styles();
        assert_eq!(styles.len(), 4);
        for s in &styles {
            s.validate().unwrap();
            assert_eq!(builtin_style(&s.name).as_ref(), Some(s));
        }
        assert!(builtin_style("nope").is_none());
    }
}
