"""How many float32 Newton steps the backward friction's equation U + A U / sqrt(U^2 + 1) = S needs from each start, over
A = a / eps_v = 1e-3..1e5 and S / A = 1e-3..1e3 (and 0.9..1.1 finely): the force's largest relative error after each step
against a float64 bisection. numpy only: python friction_start.py"""
import numpy as np
f32 = np.float32
A = np.logspace(-3, 5, 161)
R = np.r_[np.logspace(-3, 3, 601), np.linspace(0.9, 1.1, 201)]
AA, RR = np.meshgrid(A, R)
A32 = AA.astype(f32).ravel(); S32 = (AA * RR).astype(f32).ravel()
lo = np.zeros(S32.size); hi = S32.astype(np.float64); a64 = A32.astype(np.float64); s64 = S32.astype(np.float64)
for _ in range(200):
    mid = 0.5*(lo+hi); neg = mid + a64*mid/np.sqrt(mid*mid+1) - s64 < 0
    lo = np.where(neg, mid, lo); hi = np.where(neg, hi, mid)
uref = 0.5*(lo+hi); Fref = a64*uref/np.sqrt(uref**2+1)
def err_of(u):
    u = u.astype(np.float64); F = a64*u/np.sqrt(u*u+1)
    return np.where(Fref > 0, np.abs(F-Fref)/np.maximum(Fref, 1e-300), np.abs(F))
def newton_u(u0, n=12):
    u = u0.astype(f32); out = []
    for i in range(n):
        r = np.sqrt(u*u + 1); u = np.clip(u - (u + A32*u/r - S32)/(f32(1) + A32/(r*r*r)), f32(0), S32); out.append(u)
    return out
def newton_th(t0, n=12):
    t = t0.astype(f32); out = []
    for i in range(n):
        sh, ch = np.sinh(t), np.cosh(t)
        t = np.maximum(t - (sh + A32*sh/ch - S32)/(ch + A32/(ch*ch)), f32(0)); out.append(np.sinh(t))
    return out
def rep(name, hist):
    print(name, " ".join(f"{i+1}:{np.max(err_of(u)):.1e}" for i, u in enumerate(hist)))
t = np.minimum(S32/A32, f32(1)); uhi = np.minimum(t/np.sqrt(np.maximum(1-t*t, f32(1e-30))), S32)
slo = np.clip((S32-uhi)/A32, 0, f32(1-1e-6)); ulo = slo/np.sqrt(1-slo*slo)
lb = np.maximum(np.maximum(np.maximum(S32-A32, 0), S32/(1+A32)), ulo)
rep("u lb     ", newton_u(lb)); rep("theta lb ", newton_th(np.arcsinh(lb)))
# transition candidate: 0.9 * root of U^3 + D U^2 = A/2 approx: C = cbrt(A/2); with D: use U ~ C^1.5/sqrt(C+D) ... try a few
D = A32 - S32
C = np.cbrt(A32/2)
g = lambda u: u + A32*u/np.sqrt(u*u+1) - S32
for k in (0.5, 0.7, 0.9):
    c = k * C * np.sqrt(C / np.maximum(C + D, C*1e-3))  # U^2 (U + D) = A/2 with U ~ C sqrt(C/(C+D)) for D>=0
    c = np.minimum(c, S32)
    cs = np.where(g(c) <= 0, np.maximum(c, lb), lb)
    rep(f"u cand{k}  ", newton_u(cs))
print("--")
lb2 = np.maximum(np.maximum(S32-A32, 0), S32/(1+A32))
for k in (0.6, 0.7, 0.8):
    c = np.minimum(k * C * np.sqrt(C / np.maximum(C + D, C*1e-3)), S32)
    rep(f"no ulo {k}", newton_u(np.where(g(c) <= 0, np.maximum(c, lb2), lb2)))
    rep(f"ulo    {k}", newton_u(np.where(g(c) <= 0, np.maximum(c, lb), lb)))
