#!/usr/bin/python3
"""A one-dimensional model of V1's column (MUSL, FLIP/PIC, per-component local damping, gravity ramped over 40
transits and held to t_factor x t_ramp, 2 points per cell) for trying shape functions before they go into the core.
It is not the program: numpy, one column of points, the Jaumann rate in 1D (sigma += E L dt) or Hencky.

Shapes: linear, gimp (cpGIMP: the domain follows F), bq / bc (quadratic / cubic B-spline, ghosts folded as in the
core), bqd / bcd (the B-splines averaged over each point's domain, which follows F: exact integration of a
piecewise-constant stress over domains that tile the column).

Usage: column_1d_model.py SHAPE 8,16,32 [damping=0.5] [t_factor=2] [flip=1] [law=hencky] [ppc=2] [E=1e4]
Prints V1's norm per resolution and the observed order (doc/methods.md, "V1 target")."""
import sys, numpy as np

def Bq(r):
    a = np.abs(r)
    return np.where(a < 0.5, 0.75 - r*r, np.where(a < 1.5, 0.5*(1.5-a)**2, 0.0))
def dBq(r):
    a = np.abs(r); s = np.sign(r)
    return np.where(a < 0.5, -2*r, np.where(a < 1.5, -s*(1.5-a), 0.0))
def Mq(r):
    return np.where(r < -1.5, 0.0, np.where(r < -0.5, (r+1.5)**3/6,
           np.where(r < 0.5, 1/6 + 0.75*(r+0.5) - (r**3+0.125)/3,
           np.where(r < 1.5, 1 - (1.5-r)**3/6, 1.0))))
def Bc(r):
    a = np.abs(r)
    return np.where(a < 1, 2/3 - a*a + a**3/2, np.where(a < 2, (2-a)**3/6, 0.0))
def dBc(r):
    a = np.abs(r); s = np.sign(r)
    return np.where(a < 1, s*(-2*a + 1.5*a*a), np.where(a < 2, -s*(2-a)**2/2, 0.0))
def Mc(r):  # antiderivative of cubic B-spline from -2
    def left(r):  # r in [-2,-1]
        return (r+2)**4/24
    def mid_neg(r):  # [-1,0]: B = 2/3 - r^2 - r^3/2
        return 1/24 + 2/3*(r+1) - (r**3+1)/3 - (r**4-1)/8
    m0 = 1/24 + 2/3 - 1/3 + 1/8  # = 0.5
    def mid_pos(r):  # [0,1]: B = 2/3 - r^2 + r^3/2
        return 0.5 + 2/3*r - r**3/3 + r**4/8
    def right(r):
        return 1 - (2-r)**4/24
    return np.where(r < -2, 0.0, np.where(r < -1, left(r), np.where(r < 0, mid_neg(r),
           np.where(r < 1, mid_pos(r), np.where(r < 2, right(r), 1.0)))))
def gimp(r, lp):
    a = np.abs(r); s = np.sign(r)
    w = np.where(a < lp, 1 - (r*r + lp*lp)/(2*lp), np.where(a < 1-lp, 1-a, np.where(a < 1+lp, (1+lp-a)**2/(4*lp), 0.0)))
    dw = np.where(a < lp, -r/lp, np.where(a < 1-lp, -s, np.where(a < 1+lp, -s*(1+lp-a)/(2*lp), 0.0)))
    return w, dw

def weights(kind, s, lp, N):
    """s: positions in cell units (np,), lp half-length in cell units. Returns idx (np,K), w, dw (cell units)."""
    K = 6
    first = np.floor(s).astype(int) - 2
    idx = first[:, None] + np.arange(K)[None, :]
    r = s[:, None] - idx
    lpc = lp[:, None]
    if kind == "gimp":
        w, dw = gimp(r, lpc)
    elif kind == "linear":
        w = np.maximum(0, 1-np.abs(r)); dw = np.where(np.abs(r) < 1, -np.sign(r), 0.0)
    elif kind == "bq":
        w, dw = Bq(r), dBq(r)
    elif kind == "bqd":  # quadratic B-spline convolved with the domain
        w = (Mq(r+lpc) - Mq(r-lpc))/(2*lpc); dw = (Bq(r+lpc) - Bq(r-lpc))/(2*lpc)
    elif kind == "bc":
        w, dw = Bc(r), dBc(r)
    elif kind == "bcd":
        w = (Mc(r+lpc) - Mc(r-lpc))/(2*lpc); dw = (Bc(r+lpc) - Bc(r-lpc))/(2*lpc)
    # Ghosts folded by linear extrapolation: u_ghost = a0 u_face + a1 u_inner.
    if kind not in ("gimp", "linear"):
        for g, face, inner, a0, a1 in ((-1, 0, 1, 2, -1), (-2, 0, 1, 3, -2), (N + 1, N, N - 1, 2, -1),
                                       (N + 2, N, N - 1, 3, -2)):
            m = idx == g
            if m.any():
                rows = np.nonzero(m.any(1))[0]
                col = np.argmax(m[rows], 1)
                for arr in (w, dw):
                    val = arr[rows, col].copy()
                    arr[rows, col + (face - g)] += a0 * val
                    arr[rows, col + (inner - g)] += a1 * val
                    arr[rows, col] = 0
    w = np.where((idx < 0) | (idx > N), 0.0, w); dw = np.where((idx < 0) | (idx > N), 0.0, dw)
    return np.clip(idx, 0, N), w, dw

def run(kind, N, ppc=2, E=1e4, damping=0.05, cfl=0.5, domain=True, t_factor=2.0, flip=1.0, law="jaumann"):
    l0, rho, g0 = 10.0, 80.0, 9.81
    c = np.sqrt(E/rho); t_ramp = 40*l0/c; t_end = t_factor*t_ramp; h = l0/N
    x0 = (np.arange(N*ppc) + 0.5)*h/ppc
    x = x0.copy(); v = np.zeros_like(x); sig = np.zeros_like(x); F = np.ones_like(x)
    V0 = np.full_like(x, h/ppc); m = rho*V0; lp0 = 0.5/ppc
    dt = cfl*h/c; nsteps = int(np.ceil(t_end/dt)); dt = t_end/nsteps
    nn = N+1
    def scat(idx, vals): return np.bincount(idx.ravel(), weights=vals.ravel(), minlength=nn)
    for n in range(nsteps):
        t = n*dt
        g = -g0*min(t/t_ramp, 1.0)
        lp = lp0*F if domain else np.full_like(x, lp0)
        idx, w, dw = weights(kind, x/h, lp, N); dw = dw/h
        mi = scat(idx, m[:, None]*w)
        pi = scat(idx, (m*v)[:, None]*w)
        fi = scat(idx, -(V0*F*sig)[:, None]*dw) + mi*g
        act = mi > 1e-14*m[0]
        vi = np.where(act, pi/np.where(act, mi, 1), 0)
        fi = fi - damping*np.abs(fi)*np.sign(vi)
        vn = np.where(act, (pi + dt*fi)/np.where(act, mi, 1), 0)
        vn[0] = 0; vi[0] = 0
        # FLIP/PIC
        dv = ((vn - vi)[idx]*w).sum(1); vpic = (vn[idx]*w).sum(1)
        v = flip*(v + dv) + (1-flip)*vpic
        x = x + dt*vpic
        # MUSL remap
        pi2 = scat(idx, (m*v)[:, None]*w)
        v2 = np.where(act, pi2/np.where(act, mi, 1), 0); v2[0] = 0
        L = (v2[idx]*dw).sum(1)
        F = F*(1 + L*dt)
        if law == "jaumann":
            sig = sig + E*L*dt
        else:  # Hencky in Kirchhoff: tau = E ln F, sigma = tau/F
            sig = E*np.log(F)/F
    exact = -rho*g0*(l0 - x0)
    run.detail = (x0, x, sig, exact, F)
    return np.sum(np.abs(sig - exact)*V0)/(rho*g0*l0*np.sum(V0)), nsteps

if __name__ == "__main__":
    kind = sys.argv[1]
    Ns = [int(a) for a in sys.argv[2].split(",")]
    kw = {}
    for a in sys.argv[3:]:
        k, val = a.split("=")
        kw[k] = float(val) if k not in ("law",) else val
        if k == "domain": kw[k] = bool(int(val))
        if k == "ppc": kw[k] = int(val)
    prev = None
    for N in Ns:
        e, ns = run(kind, N, **kw)
        print(f"{kind} N={N} steps={ns} error={e:.4e}" + (f" order={np.log2(prev/e):.2f}" if prev else ""), flush=True)
        prev = e
