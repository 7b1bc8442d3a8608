"""Seed 003, Table 2's point D (2000 rpm, 1.36 mm): what the paper's expected reduction of 24.9 %
requires of the stability paths, computed independently of the Rust code (numpy only).

    python3 crates/updating/examples/karandikar_point_d.py

Section 2 takes our nominal-kt limits at 2000 and 1000 rpm against C, as printed by
`cargo run --release -p chatter-updating --example karandikar`, and reproduces our D and B from
them alone (the Rust value-of-information code is not used). Section 3 is the argument of
`chatter_updating::karandikar`'s module docs: within 003 Eq. 1 (added damping C b / V) the
paper's D is inconsistent with its B and its Fig. 8 numbers at 1000 rpm.

Idealised paths: the limit at a speed is a function b(C) of C alone (kt, kn spread ignored: their
sd is 3.7 % / 2.7 %), C ~ U(0.5e5, 10e5), one-sided Gaussian kernel sigma = 0.5 mm (003 Eq. 3-4),
P_s = share of paths whose limit is above the test depth, expected reduction
P_s (1 - sd_S / sd_0) + (1 - P_s) (1 - sd_U / sd_0) in per cent.
"""
import numpy as np

u = (np.arange(400000) + 0.5) / 400000
C = 0.5e5 + 9.5e5 * u  # N/m
SD0 = C.std()
SIGMA = 0.5  # mm


def voi(b, bt):
    b = np.minimum(b, 7.5)
    ps = np.mean(b >= bt)
    red = []
    for stable in (True, False):
        tail = np.exp(-(b - bt) ** 2 / (2 * SIGMA**2))
        l = np.where(b >= bt, 1.0, tail) if stable else np.where(b < bt, 1.0, tail)
        w = l / l.sum()
        m = (w * C).sum()
        red.append(100 * (1 - np.sqrt((w * (C - m) ** 2).sum()) / SD0))
    return ps, ps * red[0] + (1 - ps) * red[1]


print("1. linear limit b(C) through 1.36 mm at the paths' median C, span over the prior:")
for g in [0.5, 0.66, 1.0, 2.0, 3.0, 4.0]:
    ps, r = voi(1.36 + g * (u - 0.48), 1.36)
    print(f"   span {g:4.2f} mm: P_s {ps:.2f}, expected reduction {r:5.1f} %")

print("2. ours: nominal-kt limits at 2000 rpm (examples/karandikar.rs), interpolated in C:")
cs = np.array([0.5e5, 2.5e5, 5e5, 7.5e5, 10e5])
ours = {2000: [1.15, 1.23, 1.35, 1.52, 1.81], 1000: [0.84, 0.99, 1.42, 7.5, 7.5]}
ps, r = voi(np.interp(C, cs, ours[2000]), 1.36)
print(f"   D: P_s {ps:.2f}, expected reduction {r:.1f} % (ours from the paths: 0.51 / 1.6 %)")
ps, r = voi(np.interp(C, cs, ours[1000]), 2.68)
print(f"   B: P_s {ps:.2f}, expected reduction {r:.1f} % (ours from the paths: 0.46 / 45.7 %)")


def hyperbola(b1, c1, b2, c2):
    """b0, Cc of b = b0 / (1 - C / Cc) through (c1, b1) and (c2, b2)."""
    cc = (b2 * c2 - b1 * c1) / (b2 - b1)
    return b1 * (1 - c1 / cc), cc


print("3. process damping at a lobe floor: b = b0 / (1 - C / Cc) (b proportional to the total")
print("   damping, zeta + C b / (V m omega) ...), so Cc(n) ~ n zeta / b0(n) (003 Eq. 1: C / V).")
q = lambda p: 0.5e5 + 9.5e5 * (1 - p)  # the C above which a share p of the paths lies
b0_1000, cc_1000 = hyperbola(2.68, q(0.51), 4.0, q(0.25))  # B and Fig. 8 (1000 rpm, 4 mm: 0.25)
b0_400, cc_400 = hyperbola(1.28, q(0.9), 4.0, q(0.7))  # A and Fig. 7 (400 rpm, 4 mm: 0.7)
print(f"   the paper's 1000 rpm numbers (B, 4 mm): b0 {b0_1000:.3f} mm, Cc {cc_1000:.3e} N/m")
print(f"   the paper's  400 rpm numbers (A, 4 mm): b0 {b0_400:.3f} mm, Cc {cc_400:.3e} N/m")
# D with the 1000 rpm floor scaled by Eq. 1: Cc(2000) = Cc(1000) * 2 * b0(1000) / b0(2000)
cd = q(0.52)
x = 1.36 / (1 + 1.36 * cd / (2 * cc_1000 * b0_1000))
cc2 = 2 * cc_1000 * b0_1000 / x
ps, r = voi(x / (1 - C / cc2), 1.36)
print(f"   D from the 1000 rpm floor and C / V: b0 {x:.3f} mm, Cc {cc2:.3e}: limit "
      f"{x / (1 - 0.5e5 / cc2):.2f}-{x / (1 - 10e5 / cc2):.2f} mm, P_s {ps:.2f}, reduction {r:.1f} %")
pred400 = cc_1000 * 0.4 * b0_1000 / b0_400
print(f"   check of the floor model on the paper's own A/B pair: Cc(400) from Cc(1000) "
      f"{pred400:.3e}, from A and Fig. 7 {cc_400:.3e} (x{pred400 / cc_400:.1f})")
print("   hyperbolas through D (P_s 0.52 at 1.36 mm), by b0: the Cc and span that 24.9 % needs")
for b0 in [1.2, 1.0, 0.8, 0.6, 0.5, 0.4, 0.3]:
    cc = cd / (1 - b0 / 1.36)
    ps, r = voi(np.where(C < cc, b0 / np.abs(1 - C / cc), np.inf), 1.36)
    pred = 2 * cc_1000 * b0_1000 / b0
    print(f"   b0 {b0:.2f} mm: Cc {cc:.3e} N/m, P_s {ps:.2f}, reduction {r:5.1f} %; "
          f"Cc from the 1000 rpm floor and C / V {pred:.3e} (x{pred / cc:.1f})")
