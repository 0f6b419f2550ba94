"""Transformation of radiance between frames: the searchlight effect.

Weiskopf, Kraus, Ruder 1999, eqs. 13-15 and 18-19, written for ``D = nu_received / nu_emitted``
(docs/physics.md, "Radiance"). Blackbody colours and RGB spectra live in :mod:`.spectral`.
"""

import numpy as np

from .arrays import ArrayLike, FloatArray, Spectrum
from .validation import finite_array, positive_array


def _doppler(doppler: ArrayLike) -> FloatArray:
    return positive_array(doppler, "doppler")


def received_solid_angle(emitted_solid_angle: ArrayLike, doppler: ArrayLike) -> FloatArray:
    """dOmega_received = dOmega_emitted / D^2 (Weiskopf et al. eq. 13)."""
    return finite_array(emitted_solid_angle, "emitted_solid_angle") / _doppler(doppler) ** 2


def transform_frequency_radiance(radiance_per_frequency: ArrayLike, doppler: ArrayLike) -> FloatArray:
    """Energy-dependent (per unit frequency) radiance: L_nu,obs(D nu) = D^3 L_nu,emit(nu)."""
    return _doppler(doppler) ** 3 * finite_array(radiance_per_frequency, "radiance_per_frequency")


def transform_integrated_radiance(radiance: ArrayLike, doppler: ArrayLike) -> FloatArray:
    """Integrated radiance: L_obs = D^4 L_emit (the searchlight effect, Weiskopf et al. eq. 15)."""
    return _doppler(doppler) ** 4 * finite_array(radiance, "radiance")


def chang_integrated_radiance(radiance: ArrayLike, doppler: ArrayLike) -> FloatArray:
    """Chang et al. (1996)'s searchlight, L_obs = D L_emit: wrong by D^3 (Weiskopf et al. section 3).

    Kept only to show the published mistake side by side with :func:`transform_integrated_radiance`.
    """
    return _doppler(doppler) * finite_array(radiance, "radiance")


def transform_spectral_radiance(
    emitted_spectral_radiance: Spectrum, wavelength: ArrayLike, doppler: ArrayLike
) -> FloatArray:
    """Wavelength-dependent radiance: L_lambda,obs(lambda) = D^5 L_lambda,emit(lambda D).

    ``emitted_spectral_radiance`` is a callable of wavelength (same units as ``wavelength``),
    defined wherever ``lambda * D`` falls: a spectrum known only in the visible must be extended
    by the caller first (docs/physics.md).
    """
    wavelength = positive_array(wavelength, "wavelength")
    doppler = _doppler(doppler)
    emitted = finite_array(emitted_spectral_radiance(wavelength * doppler), "emitted spectral radiance")
    result: FloatArray = doppler**5 * emitted
    return result


def point_light_irradiance(
    intensity: ArrayLike, doppler: ArrayLike, cos_incidence: ArrayLike, distance: ArrayLike
) -> FloatArray:
    """Irradiance on a surface from a point light moving relative to it (Weiskopf et al. eq. 19).

    E = D^4 cos(alpha) / r^2 * I, with ``intensity`` I the light's (isotropic) intensity in its
    own frame, ``doppler`` D of the light travelling from the light to the surface, and the
    incidence cosine and distance measured in the surface's frame at the retarded time. Light
    arriving from behind the surface (cos < 0) gives zero.
    """
    i = finite_array(intensity, "intensity")
    cosine = finite_array(cos_incidence, "cos_incidence")
    r = positive_array(distance, "distance")
    result: FloatArray = _doppler(doppler) ** 4 * np.maximum(cosine, 0.0) / r**2 * i
    return result


def spectral_point_light_irradiance(
    emitted_spectral_intensity: Spectrum,
    wavelength: ArrayLike,
    doppler: ArrayLike,
    cos_incidence: ArrayLike,
    distance: ArrayLike,
) -> FloatArray:
    """Spectral irradiance from a moving point light: E_lambda = D^5 I_lambda(lambda D) cos / r^2."""
    wavelength = positive_array(wavelength, "wavelength")
    doppler = _doppler(doppler)
    emitted = finite_array(emitted_spectral_intensity(wavelength * doppler), "emitted spectral intensity")
    cosine = finite_array(cos_incidence, "cos_incidence")
    r = positive_array(distance, "distance")
    result: FloatArray = doppler**5 * emitted * np.maximum(cosine, 0.0) / r**2
    return result
