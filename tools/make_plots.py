"""The docs' plots, from the physics core: D and D^4 against angle, the aberration of a grid of
directions, the blackbody colour seen against D, a fly-through's speed and gamma against frame.

    .venv-docs/bin/python tools/make_plots.py [--out docs/images/plots]

Needs matplotlib (requirements/docs.txt: python3.11 -m venv .venv-docs && .venv-docs/bin/pip
install -r requirements/docs.txt); the add-on itself does not. Every curve is computed with
relativity_addon.physics (docs/physics.md), never typed in.
"""

import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from relativity_addon.physics import doppler, lorentz, proper_time, spectral  # noqa: E402

SPEEDS = (0.3, 0.6, 0.9, 0.99)


def _figure(plt, width=7.0, height=4.2):
    figure, axes = plt.subplots(figsize=(width, height), dpi=110)
    axes.grid(True, alpha=0.3)
    return figure, axes


def doppler_against_angle(plt, path):
    """D and D^4 for light reaching the moving observer from angle theta' to the motion (camera frame)."""
    figure, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.2), dpi=110)
    angles = np.linspace(0.0, 180.0, 361)
    radians = np.radians(angles)
    # Viewing direction d' at theta' from the motion: the photon propagates along k' = -d'.
    k_observed = -np.stack([np.cos(radians), np.sin(radians), np.zeros_like(radians)], axis=-1)
    for speed in SPEEDS:
        d = doppler.doppler_factor_from_observed_direction(k_observed, (speed, 0.0, 0.0))
        left.plot(angles, d, label=f"{speed}c")
        right.plot(angles, d**4, label=f"{speed}c")
    for axes, title in ((left, "Doppler factor D"), (right, "Searchlight D^4 (radiance)")):
        axes.set_yscale("log")
        axes.set_xlabel("angle between view and motion, camera frame (degrees)")
        axes.set_title(title)
        axes.axhline(1.0, color="k", lw=0.8)
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
    figure.tight_layout()
    figure.savefig(path)


def aberration_map_lines(speed=0.9, step_deg=15):
    """The lines of constant scene-frame longitude and latitude, every ``step_deg`` degrees, as the
    observer moving at ``speed`` toward longitude 0, latitude 0 sees them: a list of
    (kind, longitude seen, latitude seen), kind "latitude" or "longitude", in degrees.

    A line that leaves the map at one edge comes back at the other: the seen longitude wraps at
    +-180 degrees, or the line passes a pole. NaN breaks it there, so that no segment is drawn
    across the map. The meridian behind the observer lies on both edges, +-180 degrees: it is
    drawn as both, longitude -180 and +180."""
    beta = np.array([speed, 0.0, 0.0])

    def seen(longitude, latitude):
        view = np.stack(
            [np.cos(latitude) * np.cos(longitude), np.cos(latitude) * np.sin(longitude), np.sin(latitude)], axis=-1
        )
        view_observed = -lorentz.aberrate(-view, beta)  # photons travel against the view direction
        # aberration along x keeps the sign of y: on the meridians 0 and +-180 (y ~ 1e-16 of either
        # sign after rounding) take it from the scene longitude, so that -180 and +180 keep their edges
        side = np.where(
            np.abs(view_observed[..., 1]) < 1e-12, np.copysign(0.0, np.sin(longitude)), view_observed[..., 1]
        )
        return (
            np.degrees(np.arctan2(side, view_observed[..., 0])),
            np.degrees(np.arcsin(np.clip(view_observed[..., 2], -1.0, 1.0))),
        )

    def broken(kind, x, y):
        jumps = np.nonzero(np.abs(np.diff(x)) > 90.0)[0] + 1
        return kind, np.insert(x, jumps, np.nan), np.insert(y, jumps, np.nan)

    lines = []
    fine = np.radians(np.linspace(-179.9, 179.9, 721))
    for latitude in np.radians(np.arange(-90 + step_deg, 90, step_deg)):
        lines.append(broken("latitude", *seen(fine, np.full_like(fine, latitude))))
    fine_latitude = np.radians(np.linspace(-89.9, 89.9, 361))
    for longitude in np.radians(np.arange(-180, 181, step_deg)):
        lines.append(broken("longitude", *seen(np.full_like(fine_latitude, longitude), fine_latitude)))
    return lines


def aberration_map(plt, path, speed=0.9):
    """Lines of constant longitude and latitude of the scene-frame sky, as the moving observer
    sees them (motion toward longitude 0, latitude 0), equirectangular."""
    figure, axes = _figure(plt, 9.0, 4.8)
    colours = {"latitude": "tab:blue", "longitude": "tab:orange"}
    for kind, x, y in aberration_map_lines(speed):
        axes.plot(x, y, color=colours[kind], lw=0.8)
    axes.set_xlim(-180, 180)
    axes.set_ylim(-90, 90)
    axes.set_xlabel("longitude seen (degrees; motion toward 0)")
    axes.set_ylabel("latitude seen (degrees)")
    axes.set_title(f"A 15-degree grid of the sky seen at {speed}c (blue: latitudes, orange: longitudes)")
    figure.tight_layout()
    figure.savefig(path)


def _srgb(rgb):
    rgb = np.clip(rgb, 0.0, None)
    rgb = rgb / max(rgb.max(), 1e-30)
    return np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * np.power(rgb, 1 / 2.4) - 0.055)


def blackbody_against_doppler(plt, path, temperatures=(3000.0, 5762.0, 10000.0)):
    """Colour (normalised to unit brightness) and visible brightness Y(D T) / Y(T) against D."""
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(9.0, 5.0), dpi=110, gridspec_kw={"height_ratios": (1, 1.3)})
    factors = np.geomspace(0.25, 4.0, 121)
    for row, temperature in enumerate(temperatures):
        colours = np.array([_srgb(spectral.blackbody_linear_rgb(d * temperature, gamut_map=True)) for d in factors])
        top.imshow(
            colours[None, :, :], extent=(np.log2(factors[0]), np.log2(factors[-1]), row, row + 0.9), aspect="auto"
        )
        bottom.plot(factors, spectral.blackbody_luminance_ratio(temperature, factors), label=f"{temperature:g} K")
    top.set_xlim(np.log2(factors[0]), np.log2(factors[-1]))
    top.set_ylim(0, len(temperatures))
    top.set_yticks([row + 0.45 for row in range(len(temperatures))], [f"{t:g} K" for t in temperatures])
    top.set_xticks(np.log2([0.25, 0.5, 1, 2, 4]), ["0.25", "0.5", "1", "2", "4"])
    top.set_title("A blackbody at T seen as a blackbody at D T: colour (top), visible brightness (bottom)")
    bottom.plot(factors, factors**4, "k--", lw=0.8, label="D^4 (bolometric)")
    bottom.set_xscale("log", base=2)
    bottom.set_yscale("log")
    bottom.set_xlabel("Doppler factor D")
    bottom.set_ylabel("Y(D T) / Y(T)")
    bottom.grid(True, which="both", alpha=0.3)
    bottom.legend()
    figure.tight_layout()
    figure.savefig(path)


def flythrough_speed(plt, path, frames=48, fps=24.0, beta_max=0.95, c=10.0):
    """The fly-through example's camera (examples/flythrough.py defaults): constant proper
    acceleration for 60 % of the shot, then cruise; speed, gamma and the traveller's time."""
    t_cruise = 0.6 * (frames - 1) / fps
    u_max = beta_max / math.sqrt(1.0 - beta_max**2)
    acceleration = c * u_max / t_cruise
    frame = np.linspace(1.0, frames, 400)
    t = (frame - 1.0) / fps
    u = acceleration * np.minimum(t, t_cruise) / c  # gamma beta
    beta = u / np.sqrt(1.0 + u * u)
    gamma = np.sqrt(1.0 + u * u)
    tau = proper_time.proper_times(t, beta)
    figure, left = plt.subplots(figsize=(8.0, 4.2), dpi=110)
    left.plot(frame, beta, label="speed (c)")
    left.plot(frame, t / t[-1], label=f"scene time (of {t[-1]:.2f} s)")
    left.plot(frame, tau / t[-1], label=f"traveller's time (of {t[-1]:.2f} s)")
    left.set_xlabel("frame")
    left.set_ylim(0, 1.05)
    left.grid(True, alpha=0.3)
    right = left.twinx()
    right.plot(frame, gamma, color="tab:red", label="gamma")
    right.set_ylabel("gamma", color="tab:red")
    lines = left.get_legend_handles_labels()[0] + right.get_legend_handles_labels()[0]
    left.legend(lines, [line.get_label() for line in lines], loc="center right")
    left.set_title(f"examples/flythrough.py: {frames} frames at {fps:g} fps, cruise at {beta_max}c")
    figure.tight_layout()
    figure.savefig(path)


PLOTS = {
    "doppler_against_angle.png": doppler_against_angle,
    "aberration_map.png": aberration_map,
    "blackbody_against_doppler.png": blackbody_against_doppler,
    "flythrough_speed.png": flythrough_speed,
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join("docs", "images", "plots"))
    options = parser.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(options.out, exist_ok=True)
    for name, plot in PLOTS.items():
        path = os.path.join(options.out, name)
        plot(plt, path)
        plt.close("all")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
