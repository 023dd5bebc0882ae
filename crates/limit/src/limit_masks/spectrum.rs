//! [`surface_spectrum`]: the eigenvalue test of a surface scheme's local subdivision matrix
//! at an interior vertex of a valence (Reif's necessary conditions for a C¹ limit there),
//! for every scheme that has one: what `subd analyze --surface` and `subd.analyze` report.

use serde::Serialize;
use subd_schemes::Scheme;

use crate::LimitError;
use crate::limit_masks::eigen::{RingFeature, eigenvalues, ring_matrix};
use crate::split_limits::split_eigen::{FourierEigenvalue, SpectrumTest, split_spectrum};

/// The valences the test takes.
pub const VALENCES: std::ops::RangeInclusive<usize> = 3..=64;

/// Catmull-Clark's or Loop's spectrum at a valence.
#[derive(Debug, Clone, Serialize)]
pub struct RingSpectrum {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The valence.
    pub valence: usize,
    /// Eigenvalue moduli, largest first.
    pub eigenvalues: Vec<f64>,
    /// λ₁ = 1 > λ₂ = λ₃ > |λ₄|.
    pub passes: bool,
}

/// A split scheme's spectrum at a valence, by Fourier blocks.
#[derive(Debug, Clone, Serialize)]
pub struct SplitSpectrumReport {
    /// The scheme's name.
    pub scheme: &'static str,
    /// The valence (sides of the centre face for Doo-Sabin).
    pub valence: usize,
    /// The butterfly's tension.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tension: Option<f64>,
    /// Steps the matrix covers (2 for √3, whose single step turns the mesh).
    pub steps: usize,
    /// Size of the invariant neighbourhood.
    pub ball_size: usize,
    /// Every eigenvalue with its Fourier frequency, largest modulus first.
    pub eigenvalues: Vec<FourierEigenvalue>,
    /// The verdict.
    pub test: SpectrumTest,
}

/// The eigenvalue test of one scheme at one valence.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum SurfaceSpectrum {
    /// Catmull-Clark or Loop.
    Ring(RingSpectrum),
    /// Doo-Sabin, √3 or a butterfly.
    Split(SplitSpectrumReport),
}

/// The eigenvalue test of `scheme` at an interior vertex of valence `valence` (3 to 64).
///
/// ```
/// use subd_limit::spectrum::{surface_spectrum, SurfaceSpectrum};
/// use subd_schemes::Scheme;
///
/// let SurfaceSpectrum::Ring(cc) = surface_spectrum(&Scheme::CatmullClark, 5).unwrap() else {
///     unreachable!()
/// };
/// assert!(cc.passes && (cc.eigenvalues[0] - 1.0).abs() < 1e-12);
/// ```
///
/// # Errors
/// [`LimitError::Param`] for a valence out of range; the scheme's own error where it has no
/// local subdivision matrix (Bilinear, the two-phase scheme).
pub fn surface_spectrum(scheme: &Scheme, valence: usize) -> Result<SurfaceSpectrum, LimitError> {
    if !VALENCES.contains(&valence) {
        return Err(LimitError::Param(format!(
            "valence {valence}: must be {} to {}",
            VALENCES.start(),
            VALENCES.end()
        )));
    }
    match scheme {
        Scheme::CatmullClark | Scheme::Loop => ring(scheme, valence).map(SurfaceSpectrum::Ring),
        _ => {
            let spectrum = split_spectrum(scheme, valence)?;
            Ok(SurfaceSpectrum::Split(SplitSpectrumReport {
                scheme: scheme.name(),
                valence,
                tension: scheme.tension(),
                steps: scheme.period(),
                ball_size: spectrum.ball_size,
                test: spectrum.test(),
                eigenvalues: spectrum.eigenvalues,
            }))
        }
    }
}

/// Catmull-Clark's or Loop's test: the moduli of the smooth ring matrix's eigenvalues.
fn ring(scheme: &Scheme, n: usize) -> Result<RingSpectrum, LimitError> {
    let m = ring_matrix(scheme, n, RingFeature::Smooth)?;
    let ev = eigenvalues(&m)?;
    let mods: Vec<f64> = ev.iter().map(|z| z.norm()).collect();
    let tol = 1e-9;
    let passes = mods.len() >= 4
        && (ev[0].re - 1.0).abs() < tol
        && ev[0].im.abs() < tol
        && mods[1] < 1.0 - tol
        && (mods[1] - mods[2]).abs() < tol
        && mods[3] < mods[2] - tol;
    Ok(RingSpectrum {
        scheme: scheme.name(),
        valence: n,
        eigenvalues: mods,
        passes,
    })
}
