use super::*;

fn test_at(scheme: &Scheme, n: usize) -> SpectrumTest {
    split_spectrum(scheme, n).unwrap().test()
}

/// Dyn, Levin and Gregory's butterfly is C¹ only for valences 4 to 7: at valence 3 the
/// subdominant eigenvalue ¼ is not double, above 7 a pair of higher frequency dominates.
#[test]
fn classic_butterfly_fails_at_three_and_above_seven() {
    for n in 3..=16 {
        let t = test_at(&Scheme::BUTTERFLY, n);
        assert_eq!(t.passes, (4..=7).contains(&n), "valence {n}: {t:?}");
        if n >= 8 {
            // Frequency 2 from valence 8, frequency 3 from valence 14.
            assert!(t.subdominant_frequency >= 2, "valence {n}: {t:?}");
        }
    }
    // The regular case is the three-direction box spline's neighbour: λ = ½.
    assert!((test_at(&Scheme::BUTTERFLY, 6).subdominant - 0.5).abs() < 1e-12);
}

/// Zorin's rules put the subdominant eigenvalue at exactly ½ at every valence.
#[test]
fn modified_butterfly_is_c1_at_every_valence() {
    for n in 3..=20 {
        let t = test_at(&Scheme::ModifiedButterfly, n);
        assert!(t.passes, "valence {n}: {t:?}");
        assert!((t.subdominant - 0.5).abs() < 1e-12, "valence {n}: {t:?}");
    }
}

/// Doo-Sabin's weights give the face circulant the eigenvalues 1, ½, ½ and ¼ at every
/// other frequency; the
/// whole neighbourhood keeps ½ subdominant.
#[test]
fn doo_sabin_is_c1_with_one_half() {
    for n in 3..=16 {
        let t = test_at(&Scheme::DooSabin, n);
        assert!(t.passes, "valence {n}: {t:?}");
        assert!((t.subdominant - 0.5).abs() < 1e-12, "valence {n}: {t:?}");
    }
}

/// √3 over two steps: the ring of centroids scales frequency k by (1 + ω^k)/3, so the
/// subdominant eigenvalue of two steps is 4cos²(π/n)/9 (Kobbelt 2000, §3).
#[test]
fn sqrt3_is_c1_with_kobbelts_eigenvalue() {
    for n in 3..=20 {
        let t = test_at(&Scheme::Sqrt3, n);
        let expected = 4.0 * (std::f64::consts::PI / n as f64).cos().powi(2) / 9.0;
        assert!(t.passes, "valence {n}: {t:?}");
        assert!(
            (t.subdominant - expected).abs() < 1e-12,
            "valence {n}: {t:?} vs {expected}"
        );
    }
}

/// The limit mask read off the eigenvectors is Kobbelt's closed form for √3:
/// `(1 − β) p + β/n Σ p_i` with `β = 3α/(1 + 3α)`; for the butterflies it is the vertex.
#[test]
fn limit_masks_match_closed_forms() {
    for n in 3..=12 {
        let m = local_masks(&Scheme::Sqrt3, n).unwrap();
        let a = subd_schemes::split_schemes::sqrt3::alpha(n);
        let beta = 3.0 * a / (1.0 + 3.0 * a);
        assert!((m.limit[0] - (1.0 - beta)).abs() < 1e-12, "valence {n}");
        for j in 1..=n {
            assert!((m.limit[j] - beta / n as f64).abs() < 1e-12, "valence {n}");
        }
        assert!(m.limit[n + 1..].iter().all(|w| w.abs() < 1e-12));
        for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
            let m = local_masks(&scheme, n).unwrap();
            assert!((m.limit[0] - 1.0).abs() < 1e-12, "{scheme:?} {n}");
            assert!(m.limit[1..].iter().all(|w| w.abs() < 1e-12));
        }
    }
}

/// Modified butterfly at an extraordinary vertex: Zorin's rule only reads the 1-ring, so
/// its tangents are the ring's first Fourier coefficient (cos and sin weights, turned).
#[test]
fn modified_butterfly_tangents_are_ring_fourier_modes() {
    for n in [3, 4, 5, 7, 9] {
        let m = local_masks(&Scheme::ModifiedButterfly, n).unwrap();
        let [t1, t2] = m.tangents.unwrap();
        assert!(t1[0].abs() < 1e-12 && t2[0].abs() < 1e-12);
        assert!(
            t1[n + 1..]
                .iter()
                .chain(&t2[n + 1..])
                .all(|w| w.abs() < 1e-12)
        );
        // A combination a·cos + b·sin of the ring angle, the same for both masks up to a
        // turn: check that each is orthogonal to the constant and to frequency 2.
        for t in [&t1, &t2] {
            let sum: f64 = t[1..=n].iter().sum();
            assert!(sum.abs() < 1e-12);
            let c2: f64 = (0..n)
                .map(|j| t[1 + j] * (2.0 * TAU * j as f64 / n as f64).cos())
                .sum();
            // (At valences 3 and 4 frequency 2 aliases frequency 1 or 0.)
            assert!(c2.abs() < 1e-12 || n < 5, "valence {n}");
        }
    }
    // The classic butterfly at valence 8 is not C¹: no tangents.
    assert!(
        local_masks(&Scheme::BUTTERFLY, 8)
            .unwrap()
            .tangents
            .is_none()
    );
}

/// At a boundary vertex the eigenvectors of the dense local matrix give √3's cubic
/// B-spline limit `(p₋₁ + 4p + p₁)/6` and the butterflies' vertex itself, with tangents
/// (the boundary is smooth).
#[test]
fn boundary_masks_match_the_curve_rules() {
    for faces in 1..=6 {
        let centre = FeatureCentre::Boundary { faces };
        let m = feature_masks(&Scheme::Sqrt3, centre).unwrap();
        // Labels: 0 the vertex, 1 its outgoing boundary neighbour, faces + 1 the other.
        assert!(
            (m.limit[0] - 4.0 / 6.0).abs() < 1e-12,
            "{faces}: {:?}",
            m.limit
        );
        assert!((m.limit[1] - 1.0 / 6.0).abs() < 1e-12, "{faces}");
        assert!((m.limit[faces + 1] - 1.0 / 6.0).abs() < 1e-12, "{faces}");
        let rest: f64 = m.limit.iter().map(|w| w.abs()).sum::<f64>() - 1.0;
        assert!(rest.abs() < 1e-12, "{faces}: only three weights");
        // A lone triangle at a corner of the mesh has no subdominant pair; from six
        // triangles on, √3's along-the-boundary eigenvalue ⅓ is double and defective
        // below the cross one, and no tangent pair is given.
        assert_eq!(
            m.tangents.is_some(),
            (2..=5).contains(&faces),
            "√3 boundary {faces}"
        );
        for scheme in [Scheme::BUTTERFLY, Scheme::ModifiedButterfly] {
            let m = feature_masks(&scheme, centre).unwrap();
            assert!((m.limit[0] - 1.0).abs() < 1e-12, "{scheme:?} {faces}");
            assert!(
                faces == 1 || m.tangents.is_some(),
                "{scheme:?} boundary {faces}"
            );
        }
    }
}

/// A dart's limit mask sums to 1 and is the eigenvalue-1 left eigenvector of its
/// local matrix.
#[test]
fn dart_masks_are_left_eigenvectors() {
    for valence in [4, 5, 6, 7] {
        for scheme in [Scheme::Sqrt3, Scheme::ModifiedButterfly] {
            let m = feature_masks(&scheme, FeatureCentre::Dart { valence }).unwrap();
            let sum: f64 = m.limit.iter().sum();
            assert!((sum - 1.0).abs() < 1e-12);
            for j in 0..m.limit.len() {
                let lj: f64 = (0..m.limit.len())
                    .map(|i| m.limit[i] * m.matrix[(i, j)])
                    .sum();
                assert!((lj - m.limit[j]).abs() < 1e-12, "{scheme:?} {valence}");
            }
        }
    }
}

#[test]
fn valence_out_of_range_is_an_error() {
    assert!(split_spectrum(&Scheme::Sqrt3, 2).is_err());
    assert!(split_spectrum(&Scheme::Sqrt3, 65).is_err());
}
