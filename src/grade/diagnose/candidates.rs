//! Which fault sets are worth rendering for a render of the rubric: every single fault the scene
//! can show in a picture the rubric takes from it (families with their common members), then,
//! for images no single fault explains, the rest of each promising family and pairs of the
//! faults that explain part of the image.

use crate::case::Case;
use crate::fault::{Fault, FaultSet, Flip, Gamma, Length, Mapping, Parameter};
use crate::film::Picture;
use crate::pipeline::fault_applies;

/// The single faults to try first: each fault that applies to the scene and can change one of
/// `pictures`, families with their usual members.
pub fn singles(case: &Case, pictures: &[Picture]) -> Vec<FaultSet> {
    let mut sets = Vec::new();
    for fault in Fault::ALL {
        let can = fault.pictures();
        let shows = pictures.iter().any(|p| p.among(can));
        if !shows || !fault_applies(case, fault) {
            continue;
        }
        sets.extend(members(case, fault).into_iter().take(usual_members(fault)));
    }
    sets
}

/// How many of a family's [`members`] are tried with the single faults; the rest only when the
/// family looks promising.
fn usual_members(fault: Fault) -> usize {
    match fault {
        Fault::GammaApplied | Fault::SpecularUnnormalizedReflection => 2,
        _ => usize::MAX,
    }
}

/// A fault's members, the usual ones first: `[fault]` for a fault that is not a family.
pub fn members(case: &Case, fault: Fault) -> Vec<FaultSet> {
    let with = |p: Parameter| FaultSet::NONE.with(p);
    match fault {
        Fault::GammaApplied => [Gamma::Srgb, Gamma::Power(2.2)]
            .map(|g| with(Parameter::Gamma(g)))
            .to_vec(),
        Fault::SpecularUnnormalizedReflection => [2.0, -1.0, 0.5, 1.5, 3.0, 4.0, 8.0]
            .map(|k| {
                with(Parameter::Length(if k < 0.0 {
                    Length::HitDistance
                } else {
                    Length::Factor(k)
                }))
            })
            .to_vec(),
        Fault::PixelMapping => [Mapping::Centres, Mapping::UpsideDown, Mapping::Mirrored]
            .map(|m| with(Parameter::Mapping(m)))
            .to_vec(),
        Fault::CubemapFaceFlipped => [Flip::Vertical, Flip::Horizontal]
            .map(|f| with(Parameter::Flip(f)))
            .to_vec(),
        Fault::WrongBounces => {
            // One off either way first (none at all is `no-reflections`), then the others.
            let asked = case.render.trace.bounces;
            let mut counts = vec![asked + 1];
            if asked >= 2 {
                counts.push(asked - 1);
            }
            let near = [asked, asked + 1, asked.wrapping_sub(1)];
            counts.extend((1..=(asked + 3).max(4)).filter(|n| !near.contains(n)));
            counts.into_iter().map(|n| with(Parameter::Bounces(n))).collect()
        }
        _ => vec![FaultSet::single(fault)],
    }
}

/// Two sets at once, unless they share a fault (two members of one family).
pub fn pair(a: &FaultSet, b: &FaultSet) -> Option<FaultSet> {
    let shared = a.faults().any(|f| b.contains(f));
    (!shared).then(|| a.union(*b))
}
