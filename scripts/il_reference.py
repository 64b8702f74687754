#!/usr/bin/env python3
"""Independent high-precision references for the rough interfaced-Lambertian BRDF.

f(i, o) = f_s + f_b with [IL18 eq. 4] the specular lobe
    f_s = F(i.h) D(h) G(i, o, h) / (4 |i.n| |o.n|)
and [IL18 eq. 13] the body term
    f_b = K_d / (pi n_i^2 (1 - K_d r_i)) * I,
    I   = int T(i.m) T(o.m) D(m) G(i, o, m) |i.m| |o.m| / (|i.n| |o.n|) dw_m,
r_e = int_0^1 F(mu) 2 mu dmu [IL18 eq. 10] by quadrature (not Molenaar's closed form,
IL18 eq. 11), r_i from n_i^2 (1 - r_i) = 1 - r_e.

Written from the papers, sharing no code with facette: numpy only (mpmath for the
Gaussian normalization). I is integrated in (phi_m, theta_m) with Gauss-Legendre panels,
the panels cut where the integrand has kinks (a facet turning away from i or o, the
V-cavity masking [IL18 eq. 15] changing branch, and the azimuths where those limits cross
or appear), the theta panels also graded near the normal for narrow distributions. Each
value is computed with 48 and with 96 nodes per panel; the script reports the largest
relative difference of the two (the references' accuracy) and prints the 96-node values.

Usage: python3 scripts/il_reference.py > /dev/null   (prints a Rust table on stdout,
the convergence check on stderr). The table is pasted into
crates/bsdf/tests/suite/il_quadrature_reference.rs.
"""

import math
import sys

import mpmath
import numpy as np

# (name, material TOML for facette, distribution, params, masking, n_i, K_d)
CONFIGS = [
    ("beckmann-0.7-vcavity-ni1", "beckmann", (0.7, 0.7), "v-cavity", 1.0, 0.8),
    ("gaussian-0.5-vcavity-ni1", "gaussian", 0.5, "v-cavity", 1.0, 0.8),
    ("beckmann-0.3-smith-ni1.5-fig7", "beckmann", (0.3, 0.3), "smith", 1.5, 1.0),
    ("beckmann-1.0-vcavity-ni1.5-fig7", "beckmann", (1.0, 1.0), "v-cavity", 1.5, 1.0),
    ("ggx-0.5-smith-ni2", "ggx", (0.5, 0.5), "smith", 2.0, 0.6),
    ("ggx-0.2-vcavity-ni1.5", "ggx", (0.2, 0.2), "v-cavity", 1.5, 0.7),
    ("gaussian-1.0-vcavity-ni2", "gaussian", 1.0, "v-cavity", 2.0, 0.5),
    ("beckmann-aniso-0.2x0.6-smith-ni1.5", "beckmann", (0.2, 0.6), "smith", 1.5, 0.9),
    ("ggx-aniso-0.6x0.15-vcavity-ni1", "ggx", (0.6, 0.15), "v-cavity", 1.0, 0.8),
]

# (theta_i, phi_i, theta_o, phi_o) in degrees, grazing pairs included.
PAIRS = [
    (0.0, 0.0, 0.0, 0.0),
    (30.0, 0.0, 60.0, 180.0),
    (60.0, 0.0, 60.0, 0.0),
    (85.0, 0.0, 85.0, 180.0),
    (85.0, 0.0, 85.0, 0.0),
    (85.0, 0.0, 80.0, 90.0),
    (45.0, 30.0, 85.0, 200.0),
    (70.0, 0.0, 20.0, 270.0),
]


def material_toml(dist, par, masking, ni, kd):
    if dist == "gaussian":
        rough = f'distribution = "gaussian", sigma = {par}'
    elif par[0] == par[1]:
        rough = f'distribution = "{dist}", alpha = {par[0]}'
    else:
        rough = f'distribution = "{dist}", alpha_u = {par[0]}, alpha_v = {par[1]}'
    return (
        f'{{type = "il", kd = {kd}, ni = {ni}, {rough}, masking = "{masking}", '
        f'evaluation = "quadrature"}}'
    )


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def fresnel(c, n):
    """Unpolarized Fresnel reflectance of a dielectric interface, light from outside."""
    c = np.abs(c)
    g = np.sqrt(n * n - 1.0 + c * c)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


def gauss_legendre(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return x, w


class Material:
    def __init__(self, dist, par, masking, ni, kd):
        self.dist, self.par, self.masking, self.ni, self.kd = dist, par, masking, ni, kd
        if dist == "gaussian":
            s = par
            norm = mpmath.quad(
                lambda t: mpmath.exp(-t * t / (2 * s * s)) * mpmath.sin(t),
                [0, s, 2 * s, 4 * s, mpmath.pi / 2],
            )
            self.gauss_c = float(1 / (2 * mpmath.pi * norm))
            self.width = math.sqrt(2.0) * s
        else:
            self.width = math.sqrt(par[0] * par[1])
        mpmath.mp.dps = 30
        re = mpmath.quad(
            lambda mu: 2 * mu * self._fresnel_mp(mu), [0, mpmath.mpf(1) / 1000, 0.1, 1]
        )
        mpmath.mp.dps = 15
        self.re = float(re)
        self.ri = 1.0 - (1.0 - self.re) / (ni * ni)

    def _fresnel_mp(self, c):
        n = mpmath.mpf(self.ni)
        if n == 1:
            return mpmath.mpf(0)
        g = mpmath.sqrt(n * n - 1 + c * c)
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1) / (c * (g - c) + 1)
        return a * a * (1 + b * b) / 2

    def d(self, mx, my, mz):
        """The distribution of normals D(m), m in the upper hemisphere."""
        if self.dist == "gaussian":
            t = np.arccos(np.clip(mz, -1.0, 1.0))
            return self.gauss_c * np.exp(-t * t / (2 * self.par**2)) / mz
        ax, ay = self.par
        s2 = (mx / ax) ** 2 + (my / ay) ** 2
        z2 = mz * mz
        if self.dist == "beckmann":
            return np.exp(-s2 / z2) / (math.pi * ax * ay * z2 * z2)
        return 1.0 / (math.pi * ax * ay * z2 * z2 * (1.0 + s2 / z2) ** 2)

    def smith_lambda(self, v):
        ax, ay = self.par
        st = math.hypot(v[0], v[1])
        if st == 0.0:
            return 0.0
        cp, sp = v[0] / st, v[1] / st
        alpha = math.sqrt(cp * cp * ax * ax + sp * sp * ay * ay)
        a = v[2] / (alpha * st)
        if self.dist == "beckmann":
            return 0.5 * (math.erf(a) - 1.0) + math.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))
        return 0.5 * (-1.0 + math.sqrt(1.0 + 1.0 / (a * a)))

    def g(self, i, o, mx, my, mz):
        """G(i, o, m) for m facing both i and o."""
        im = i[0] * mx + i[1] * my + i[2] * mz
        om = o[0] * mx + o[1] * my + o[2] * mz
        if self.masking == "v-cavity":
            return np.minimum(
                1.0, np.minimum(2 * mz * i[2] / im, 2 * mz * o[2] / om)
            )
        return np.ones_like(mz) / ((1.0 + self.smith_lambda(i)) * (1.0 + self.smith_lambda(o)))

    def specular(self, i, o):
        h = i + o
        h = h / np.linalg.norm(h)
        ih = float(i @ h)
        f = fresnel(ih, self.ni) if self.ni > 1.0 else 0.0
        d = float(self.d(np.array(h[0]), np.array(h[1]), np.array(h[2])))
        g = float(self.g(i, o, np.array(h[0]), np.array(h[1]), np.array(h[2])))
        return f * d * g / (4.0 * i[2] * o[2])

    def body_integral(self, i, o, nodes):
        """I(i, o) of IL18 eq. 13, by break-point-split tensor Gauss-Legendre."""
        x, w = gauss_legendre(nodes)
        si, so = math.hypot(i[0], i[1]), math.hypot(o[0], o[1])
        pi_, po = math.atan2(i[1], i[0]), math.atan2(o[1], o[0])

        # Azimuthal cuts: c_i = 0, c_o = 0, and k_i s_i c_i + k_o s_o c_o = 0 for
        # (k_i, k_o) = (o_z, -i_z) (the V-cavity branches swap) and (o_z, i_z) (one
        # direction's limit crosses the other's), c_v = cos(phi - phi_v).
        cuts = {0.0, 2 * math.pi}
        for ki, ko in [(1.0, 0.0), (0.0, 1.0), (o[2], -i[2]), (o[2], i[2])]:
            a = ki * si * math.cos(pi_) + ko * so * math.cos(po)
            b = ki * si * math.sin(pi_) + ko * so * math.sin(po)
            if math.hypot(a, b) < 1e-14:
                continue
            psi = math.atan2(b, a)
            for z in (psi - math.pi / 2, psi + math.pi / 2):
                cuts.add(z % (2 * math.pi))
        cuts = sorted(cuts)
        # Each azimuthal panel is split in 4 to follow the inner integral's variation.
        phis, wphis = [], []
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            if hi - lo < 1e-15:
                continue
            sub = np.linspace(lo, hi, 5)
            for a, b in zip(sub[:-1], sub[1:]):
                phis.append(0.5 * (a + b) + 0.5 * (b - a) * x)
                wphis.append(0.5 * (b - a) * w)
        phis = np.concatenate(phis)
        wphis = np.concatenate(wphis)

        total = 0.0
        for phi, wphi in zip(phis, wphis):
            top = math.pi / 2
            tcuts = []
            for v, s, p in [(i, si, pi_), (o, so, po)]:
                sc = s * math.cos(phi - p)
                if sc < 0.0:
                    top = min(top, math.atan2(v[2], -sc))
                elif sc > 0.0:
                    tcuts.append(math.atan2(v[2], sc))
            # Graded near the normal: w/8 ... 8w and a geometric sequence below.
            tcuts += [self.width * k for k in (1 / 64, 1 / 16, 1 / 8, 0.25, 0.5, 1, 2, 4, 8)]
            tc = sorted({0.0, top} | {t for t in tcuts if 0.0 < t < top})
            thetas, wth = [], []
            for a, b in zip(tc[:-1], tc[1:]):
                if b - a < 1e-15:
                    continue
                thetas.append(0.5 * (a + b) + 0.5 * (b - a) * x)
                wth.append(0.5 * (b - a) * w)
            t = np.concatenate(thetas)
            wt = np.concatenate(wth)
            st, ct = np.sin(t), np.cos(t)
            mx, my, mz = st * math.cos(phi), st * math.sin(phi), ct
            im = i[0] * mx + i[1] * my + i[2] * mz
            om = o[0] * mx + o[1] * my + o[2] * mz
            ok = (im > 0) & (om > 0)
            tt = (1.0 - fresnel(im, self.ni)) * (1.0 - fresnel(om, self.ni))
            val = tt * self.d(mx, my, mz) * self.g(i, o, mx, my, mz) * im * om / (i[2] * o[2]) * st
            val = np.where(ok, val, 0.0)
            total += wphi * float(np.sum(wt * val))
        return total

    def prefactor(self):
        return self.kd / (math.pi * self.ni**2 * (1.0 - self.kd * self.ri))


def main():
    worst = 0.0
    print("// name, material, [theta_i, phi_i, theta_o, phi_o], f, body integral I")
    for name, dist, par, masking, ni, kd in CONFIGS:
        mat = Material(dist, par, masking, ni, kd)
        toml = material_toml(dist, par, masking, ni, kd)
        rows = []
        for pair in PAIRS:
            i, o = direction(pair[0], pair[1]), direction(pair[2], pair[3])
            lo = mat.body_integral(i, o, 48)
            hi = mat.body_integral(i, o, 96)
            rel = abs(hi - lo) / abs(hi)
            worst = max(worst, rel)
            f = mat.specular(i, o) + mat.prefactor() * hi
            rows.append((pair, float(f), float(hi)))
            print(f"{name} {pair}: I = {hi:.15e}, 48 vs 96 nodes: {rel:.1e}", file=sys.stderr)
        print(f'    ("{name}", r#"{toml}"#, &[')
        for pair, f, body in rows:
            print(f"        ([{pair[0]:.1f}, {pair[1]:.1f}, {pair[2]:.1f}, {pair[3]:.1f}], {float(f)!r}, {float(body)!r}),")
        print("    ]),")
    print(f"largest 48- vs 96-node relative difference: {worst:.2e}", file=sys.stderr)


if __name__ == "__main__":
    main()
