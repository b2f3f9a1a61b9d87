//! Tests of `tapsim::physics::law` (src/physics/law/mod.rs).

use tapsim::physics::law::registry::LawKind;
use tapsim::physics::law::*;

#[test]
fn every_law_is_registered_once_under_a_name_that_parses_back() {
    for kind in LawKind::ALL {
        assert_eq!(
            LAWS.iter().filter(|l| l.name == kind.info().name).count(),
            1,
            "{kind:?}"
        );
        assert_eq!(LawKind::from_name(&kind.to_string()), Some(kind));
    }
    assert_eq!(LAWS.len(), LawKind::ALL.len());
    assert_eq!(LawKind::from_name(" JKR "), Some(LawKind::Jkr));
    assert_eq!(LawKind::from_name("jkr2"), None);
}
