//! Property tests of the fuzzy map's algebra on random observations: merge is commutative
//! (exactly) and associative (to float tolerance), insertion order does not matter, and
//! memberships stay in [0, 1], for several operator families.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use fuzzyvox::VoxelMapMut;
use fuzzyvox::{Family, FuzzyConfig, FuzzyMap, IntegrationOptions, PointCloud, TConorm, VoxelMap};
use nalgebra::Point3;
use proptest::prelude::*;

fn family() -> impl Strategy<Value = Family> {
    prop_oneof![
        Just(Family::Product),
        Just(Family::Minimum),
        Just(Family::Lukasiewicz),
        Just(Family::Einstein),
        (0.0..10.0f64).prop_map(|gamma| Family::Hamacher { gamma }),
        (0.2..8.0f64).prop_map(|lambda| Family::Dombi { lambda }),
        (0.5..6.0f64).prop_map(|p| Family::Yager { p }),
    ]
}

/// A random scan: an origin and up to 40 points with confidences, all within a few metres.
fn scan() -> impl Strategy<Value = PointCloud> {
    let coordinate = -3.0..3.0f64;
    (
        [coordinate.clone(), coordinate.clone(), coordinate.clone()],
        prop::collection::vec(
            (
                [coordinate.clone(), coordinate.clone(), coordinate],
                0.0..=1.0f32,
            ),
            1..40,
        ),
    )
        .prop_map(|(origin, points)| {
            let (points, confidence): (Vec<_>, Vec<_>) = points
                .into_iter()
                .map(|(p, c)| (Point3::from(p), c))
                .unzip();
            PointCloud::new(Point3::from(origin), points)
                .unwrap()
                .with_confidence(confidence)
                .unwrap()
        })
}

fn map_of(family: Family, scans: &[PointCloud]) -> FuzzyMap {
    let config = FuzzyConfig::new(0.25)
        .unwrap()
        .with_operator(TConorm::new(family).unwrap());
    let mut map = FuzzyMap::new(config).unwrap();
    for s in scans {
        map.integrate_cloud(s, &IntegrationOptions::default())
            .unwrap();
    }
    map
}

fn max_difference(a: &FuzzyMap, b: &FuzzyMap) -> f32 {
    a.cells()
        .chain(b.cells())
        .map(|(key, _)| {
            let (m, n) = (a.memberships_at(key), b.memberships_at(key));
            (m.occupied - n.occupied).abs().max((m.free - n.free).abs())
        })
        .fold(0.0, f32::max)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn merge_is_commutative_exactly(family in family(), a in scan(), b in scan()) {
        let mut ab = map_of(family, std::slice::from_ref(&a));
        ab.merge(&map_of(family, std::slice::from_ref(&b))).unwrap();
        let mut ba = map_of(family, std::slice::from_ref(&b));
        ba.merge(&map_of(family, std::slice::from_ref(&a))).unwrap();
        prop_assert_eq!(ab.to_bytes(), ba.to_bytes());
    }

    #[test]
    fn merge_is_associative_and_equals_sequential_insertion(
        family in family(), a in scan(), b in scan(), c in scan()
    ) {
        let (ma, mb, mc) = (
            map_of(family, std::slice::from_ref(&a)),
            map_of(family, std::slice::from_ref(&b)),
            map_of(family, std::slice::from_ref(&c)),
        );
        let mut left = ma.clone();
        left.merge(&mb).unwrap();
        left.merge(&mc).unwrap();
        let mut right_inner = mb.clone();
        right_inner.merge(&mc).unwrap();
        let mut right = ma.clone();
        right.merge(&right_inner).unwrap();
        prop_assert!(max_difference(&left, &right) < 1e-4);
        let sequential = map_of(family, &[c.clone(), a.clone(), b.clone()]);
        prop_assert!(max_difference(&left, &sequential) < 1e-4);
        for (_, m) in left.cells() {
            prop_assert!((0.0..=1.0).contains(&m.occupied) && (0.0..=1.0).contains(&m.free));
        }
    }
}
