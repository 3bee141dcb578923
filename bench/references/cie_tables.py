#!/usr/bin/env python3
"""Prints src/scene/mitsuba/cie.rs: the CIE 1931 2-degree colour matching
functions and the D65 illuminant at 5 nm from 360 to 830 nm (the CIE's own
tabulation interval), read through Mitsuba 3's copy of the CIE tables so that
tracelab converts spectra with the very data its references were made with.

    pip install mitsuba
    python3 bench/references/cie_tables.py > src/scene/mitsuba/cie.rs
"""

import mitsuba as mi

mi.set_variant("scalar_rgb")

wavelengths = range(360, 831, 5)
rows = []
for l in wavelengths:
    x, y, z = mi.cie1931_xyz(float(l))
    d65 = mi.cie_d65(float(l))
    rows.append(f"    [{x:.6e}, {y:.6e}, {z:.6e}, {d65:.6e}],")

print("""//! CIE 1931 2° colour matching functions (x̄, ȳ, z̄) and the D65 illuminant's
//! relative spectral power, every 5 nm from 360 to 830 nm (CIE 015 tables;
//! made by `bench/references/cie_tables.py`).

/// First wavelength of [`TABLE`], nm.
pub const FIRST: f64 = 360.0;
/// Spacing of [`TABLE`], nm.
pub const STEP: f64 = 5.0;

/// x̄, ȳ, z̄ and D65 at FIRST + k × STEP.
#[rustfmt::skip]
pub const TABLE: [[f64; 4]; %d] = [""" % len(rows))
print("\n".join(rows))
print("];")
