//! The fault catalogue (`goldray::fault`): every fault changes the pictures it should, the way
//! it should, and nothing else; a fault that cannot act on a scene (no shadows to leave out)
//! changes nothing there; and rendering without faults is rendering.
//!
//! Renders are small (64×64): what is checked is which pixels move and in which direction.
//! The mirror-image and upside-down members of `pixel-mapping` are checked as flips.

use std::path::{Path, PathBuf};

use goldray::case::{AssignmentOptions, Case, LoadOptions, load, load_assignment_scene};
use goldray::fault::{Fault, FaultSet};
use goldray::film::{Film, Picture, Tonemap, picture, picture_with_faults};
use goldray::pipeline::{fault_applies, render_case, render_case_with_faults};
use goldray::progress::Silent;
use goldray::rgb_image::RgbImage;

const SIZE: u32 = 64;

/// The course's seven grading commands at 64×64, with their depth ranges.
/// Course scene `number` (1 to 7) with its graded flags; 8 is scene 01 with `-jitter -filter`,
/// for the faults that act only where those are asked for.
fn course(number: usize) -> Case {
    let sampled = number == 8;
    let number = if sampled { 1 } else { number };
    let (file, bounces, shadows) = [
        ("scene01_plane.txt", 0, false),
        ("scene02_cube.txt", 0, false),
        ("scene03_sphere.txt", 0, false),
        ("scene04_axes.txt", 0, false),
        ("scene05_bunny_200.txt", 0, false),
        ("scene06_bunny_1k.txt", 4, false),
        ("scene07_arch.txt", 4, true),
    ][number - 1];
    let options = AssignmentOptions {
        width: SIZE,
        height: SIZE,
        bounces,
        shadows,
        depth_range: Some(depth_range(number)),
        normals: true,
        jitter: sampled,
        filter: sampled,
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/mit6837").join(file);
    load_assignment_scene(&path, &options).unwrap_or_else(|e| panic!("{e}"))
}

fn depth_range(number: usize) -> (f64, f64) {
    if number == 5 { (0.8, 1.0) } else { (8.0, 18.0) }
}

fn own_scene() -> Case {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/faults/scene.toml");
    load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Colour, normals and depth of `case` rendered with `faults`.
fn pictures(case: &Case, faults: &FaultSet) -> [RgbImage; 3] {
    let film: Film = render_case_with_faults(case, faults, &Silent).unwrap_or_else(|e| panic!("{e}"));
    let (min, max) = case.render.depth_range.unwrap_or((8.0, 18.0));
    [
        Picture::Color,
        Picture::Normals,
        Picture::Depth {
            min: min as f32,
            max: max as f32,
        },
    ]
    .map(|p| picture_with_faults(&film, p, Tonemap::Clamp, faults))
}

/// How a fault moves a picture's pixels, compared with the golden picture.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Change {
    Same,
    /// Some pixel moved, none got brighter.
    Darker,
    /// Some pixel moved, none got darker.
    Brighter,
    /// Some pixels moved, either way.
    Moved,
}

fn change(golden: &RgbImage, faulty: &RgbImage) -> (Change, usize) {
    let (mut darker, mut brighter, mut moved) = (false, false, 0);
    for (g, f) in golden.pixels().zip(faulty.pixels()) {
        if g != f {
            moved += 1;
        }
        for (a, b) in g.0.iter().zip(f.0) {
            darker |= b < *a;
            brighter |= b > *a;
        }
    }
    let change = match (darker, brighter) {
        (false, false) => Change::Same,
        (true, false) => Change::Darker,
        (false, true) => Change::Brighter,
        (true, true) => Change::Moved,
    };
    (change, moved)
}

use Change::{Brighter, Darker, Moved, Same};

/// Each fault on a scene it acts on: how colour, normals and depth move.
#[test]
fn every_fault_changes_what_it_should_and_nothing_else() {
    let own = own_scene();
    let scenes: Vec<Case> = (1..=8).map(course).collect();
    let scene = |n: usize| if n == 0 { &own } else { &scenes[n - 1] };
    let expectations: &[(&str, usize, [Change; 3])] = &[
        ("specular-unnormalized-reflection=2", 1, [Brighter, Same, Same]),
        ("blinn-phong", 1, [Brighter, Same, Same]),
        ("no-specular", 1, [Darker, Same, Same]),
        ("no-ambient", 1, [Darker, Same, Same]),
        ("no-diffuse-clamp", 1, [Darker, Same, Same]),
        ("light-color-ignored", 2, [Brighter, Same, Same]),
        ("nothing-shaded", 1, [Moved, Same, Same]),
        ("flat-shading", 5, [Moved, Moved, Same]),
        ("falloff-linear", 1, [Brighter, Same, Same]),
        ("falloff-plus-one", 1, [Darker, Same, Same]),
        ("no-falloff", 1, [Moved, Same, Same]),
        ("directional-flipped", 2, [Darker, Same, Same]),
        ("point-light-missing", 0, [Darker, Same, Same]),
        ("no-shadows", 7, [Brighter, Same, Same]),
        ("shadow-acne", 7, [Darker, Same, Same]),
        ("shadows-beyond-light", 0, [Darker, Same, Same]),
        ("no-ambient-in-shadow", 7, [Darker, Same, Same]),
        ("no-reflections", 6, [Darker, Same, Same]),
        ("reflection-without-ks", 6, [Brighter, Same, Same]),
        ("reflection-on-every-material", 7, [Same, Same, Same]),
        ("reflection-acne", 6, [Moved, Same, Same]),
        ("reflected-miss-black", 6, [Darker, Same, Same]),
        ("wrong-bounces=1", 6, [Darker, Same, Same]),
        ("normals-not-inverse-transpose", 3, [Brighter, Moved, Same]),
        ("transform-direction-reversed", 3, [Moved, Moved, Darker]),
        ("transform-direction-normalized", 3, [Same, Same, Brighter]),
        ("transform-order-reversed", 3, [Moved, Moved, Moved]),
        ("plane-one-sided", 0, [Brighter, Brighter, Darker]),
        ("triangle-normal-flipped", 2, [Darker, Darker, Same]),
        ("pixel-mapping=centres", 1, [Moved, Moved, Moved]),
        ("fov-half-angle", 1, [Moved, Moved, Moved]),
        ("up-orthonormalized", 2, [Moved, Moved, Moved]),
        ("plane-missing", 1, [Darker, Darker, Darker]),
        ("triangle-missing", 2, [Moved, Darker, Darker]),
        ("transform-missing", 3, [Moved, Moved, Darker]),
        ("no-jitter", 8, [Moved, Same, Same]),
        ("no-filter", 8, [Moved, Same, Same]),
        ("gamma-applied=srgb", 1, [Brighter, Same, Same]),
        ("color-not-clamped", 1, [Darker, Same, Same]),
        ("normals-not-remapped", 1, [Same, Darker, Same]),
        ("depth-inverted", 1, [Same, Same, Moved]),
        ("depth-not-clamped", 1, [Same, Same, Moved]),
        ("depth-miss-white", 3, [Same, Same, Brighter]),
        ("cubemap-face-flipped=vertical", 6, [Moved, Same, Same]),
        ("cubemap-ignored", 6, [Darker, Same, Same]),
        ("background-missing", 0, [Darker, Same, Same]),
    ];
    let listed: Vec<Fault> = expectations
        .iter()
        .flat_map(|(text, ..)| text.parse::<FaultSet>().unwrap().faults().collect::<Vec<_>>())
        .collect();
    assert_eq!(listed, Fault::ALL, "one expectation per fault, in catalogue order");

    let goldens: Vec<[RgbImage; 3]> = (0..=8).map(|n| pictures(scene(n), &FaultSet::NONE)).collect();
    let mut failures = Vec::new();
    for &(text, n, expected) in expectations {
        let faults: FaultSet = text.parse().unwrap();
        let fault = faults.faults().next().unwrap();
        assert!(fault_applies(scene(n), fault), "{text} should apply to scene {n}");
        let faulty = pictures(scene(n), &faults);
        for (which, ((golden, faulty), want)) in goldens[n].iter().zip(&faulty).zip(expected).enumerate() {
            let (got, moved) = change(golden, faulty);
            let picture = ["colour", "normals", "depth"][which];
            if got != want {
                failures.push(format!(
                    "{text} on scene {n}: {picture} {got:?} ({moved} pixels), expected {want:?}"
                ));
            }
            let can_change = [fault.pictures().color, fault.pictures().normals, fault.pictures().depth][which];
            assert!(
                can_change || got == Same,
                "{text} changed the {picture}, which its entry rules out"
            );
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Where the catalogue says a fault cannot act on a scene, it changes nothing there: the
/// diagnosis skips such faults, and must not skip one that would have mattered.
#[test]
fn a_fault_that_does_not_apply_changes_nothing() {
    let mut skipped = 0;
    for n in 1..=7 {
        let case = course(n);
        let golden = pictures(&case, &FaultSet::NONE);
        for fault in Fault::ALL {
            if fault_applies(&case, fault) {
                continue;
            }
            skipped += 1;
            let faults = if fault == Fault::WrongBounces {
                "wrong-bounces=2".parse().unwrap()
            } else {
                FaultSet::single(fault)
            };
            for (which, (faulty, golden)) in pictures(&case, &faults).iter().zip(&golden).enumerate() {
                let (change, moved) = change(golden, faulty);
                assert_eq!(
                    change, Same,
                    "{fault} on scene {n} moved {moved} pixels of picture {which}"
                );
            }
        }
    }
    assert!(skipped > 40, "only {skipped} (fault, scene) pairs ruled out");
}

#[test]
fn orientation_faults_are_flips_of_the_golden_pictures() {
    let case = course(4);
    let golden = pictures(&case, &FaultSet::NONE);
    let upside_down = pictures(&case, &"pixel-mapping=upside-down".parse().unwrap());
    let mirrored = pictures(&case, &"pixel-mapping=mirrored".parse().unwrap());
    for i in 0..3 {
        assert!(upside_down[i] == golden[i].flipped_vertically(), "picture {i}");
        assert!(mirrored[i] == golden[i].flipped_horizontally(), "picture {i}");
    }
}

/// The faulty program's rendering of a scene with the faults' effects removed is the golden
/// one: no fault leaks into a render that does not ask for it, whichever precision.
#[test]
fn without_faults_the_film_is_the_golden_film() {
    let mut case = own_scene();
    for precision in [goldray::options::Precision::F32, goldray::options::Precision::F64] {
        case.render.precision = precision;
        let golden = render_case(&case).unwrap();
        assert!(render_case_with_faults(&case, &FaultSet::NONE, &Silent).unwrap() == golden);
        let output_only: FaultSet = "gamma-applied+pixel-mapping=upside-down+depth-inverted"
            .parse()
            .unwrap();
        assert!(render_case_with_faults(&case, &output_only, &Silent).unwrap() == golden);
        for p in [Picture::Color, Picture::Normals, Picture::Depth { min: 4.0, max: 16.0 }] {
            assert!(
                picture_with_faults(&golden, p, Tonemap::Clamp, &FaultSet::NONE) == picture(&golden, p, Tonemap::Clamp)
            );
        }
    }
}

/// Faults combine: a pair's picture carries both changes.
#[test]
fn faults_combine() {
    let case = course(7);
    let golden = pictures(&case, &FaultSet::NONE);
    let no_shadows = pictures(&case, &"no-shadows".parse().unwrap());
    let pair = pictures(&case, &"no-shadows+pixel-mapping=upside-down".parse().unwrap());
    assert!(pair[0] == no_shadows[0].flipped_vertically());
    let both = pictures(&case, &"no-shadows+no-reflections".parse().unwrap());
    let reflection = pictures(&case, &"no-reflections".parse().unwrap());
    assert!(both[0] != no_shadows[0] && both[0] != reflection[0] && both[0] != golden[0]);
}
