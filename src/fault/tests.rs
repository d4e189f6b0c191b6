use super::catalogue::OUTPUT_FAULTS;
use super::*;

#[test]
fn sets_read_and_write_the_same_text() {
    for text in [
        "none",
        "no-shadows",
        "no-shadows+gamma-applied=1.8",
        "no-specular+wrong-bounces=3",
        "gamma-applied=srgb",
        "specular-unnormalized-reflection=t",
        "pixel-mapping=upside-down+cubemap-face-flipped=horizontal",
        "cubemap-ignored=330099",
    ] {
        let set: FaultSet = text.parse().unwrap();
        assert_eq!(set.to_string(), text);
    }
    let set: FaultSet = "gamma-applied, no-shadows".parse().unwrap();
    assert_eq!(
        set.to_string(),
        "no-shadows+gamma-applied=srgb",
        "catalogue order, first member"
    );
    assert_eq!(set.id(), "no-shadows+gamma-applied");
    assert_eq!(set.len(), 2);
}

#[test]
fn bad_sets_say_what_is_wrong() {
    let error = |text: &str| text.parse::<FaultSet>().unwrap_err().to_string();
    assert!(error("no-shadow").contains("is not a fault"), "{}", error("no-shadow"));
    assert!(error("no-shadows=1").contains("takes no value"));
    assert!(error("gamma-applied=x").contains("srgb, or a positive number"));
    assert!(error("pixel-mapping=sideways").contains("upside-down"));
}

#[test]
fn every_fault_has_a_bit_a_sentence_and_a_hint() {
    let mut bits = 0;
    for fault in Fault::ALL {
        assert_eq!(bits & fault.bit(), 0, "{fault}");
        bits |= fault.bit();
        assert!(!fault.explanation().is_empty() && !fault.hint().is_empty());
        let p = fault.pictures();
        assert!(p.color || p.normals || p.depth, "{fault} changes no picture");
        let single = FaultSet::single(fault);
        assert!(single.to_string().starts_with(fault.name()));
        assert_eq!(single.to_string().contains('='), fault.is_family(), "{fault}");
    }
    assert!(Fault::ALL.len() <= 64);
    assert_eq!(INTEGRATOR_FAULTS & OUTPUT_FAULTS, 0);
}

#[test]
fn parts_split_where_the_faults_act() {
    let set: FaultSet = "no-specular+no-shadows+gamma-applied=2+pixel-mapping=upside-down"
        .parse()
        .unwrap();
    assert_eq!(set.render_part().to_string(), "no-specular+no-shadows");
    assert_eq!(
        set.output_part().to_string(),
        "pixel-mapping=upside-down+gamma-applied=2"
    );
    let centres: FaultSet = "pixel-mapping=centres".parse().unwrap();
    assert_eq!(centres.render_part(), centres);
    assert!(centres.output_part().is_empty() && !centres.has_output_faults());
    assert!(set.checks_integrator());
    assert!(!set.only(Injection::Trace).checks_integrator());
    assert!(!NoFaults.has(Fault::NoSpecular));
    assert!(set.has(Fault::NoSpecular));
    assert_eq!(set.without(Fault::GammaApplied).union(set), set);
}
