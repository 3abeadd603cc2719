"""IPOPT on the constrained suite C1-C4 (../shared/BENCHMARKS.md) and the swing-up suite's
acrobot (`acrobot-T2`, `acrobot-T2-zero` from the zero path) and the quadrotor from the zero
path (`quadrotor-f15-zero`, as `tests/planning/restoration.rs`, with `NSTEPS=50`) and the
double pendulum with a shoulder torque limit (`pendulum-tau10`, as
`tests/planning/inequalities.rs`, with `NSTEPS=50`), transcribed as
retract's optimizer transcribes it: jets x_i = (q, q') at the nodes (the ends fixed), u_i = q''
per step, the lifted midpoint (theta = 1/2) dynamics, J = sum_i h L(x_mid_i, u_i), each
constraint where examples/constrained.rs places it (node constraints as rows of g, as the
optimizer's slacks; `nodebounds=var` makes the state bounds IPOPT variable bounds, `ends=eq`
keeps the ends as variables held by equality rows, started at their data or, with
`endguess=curve`, at the guess curve's jets there), the suite's first guesses. The reference for the acceptance of issue 30 (cost no worse, at most
1.5 times IPOPT's iterations).

Needs CasADi (`pip install casadi`; not a dependency of the project).

    python3 validation/ipopt/constrained_suite.py all            # IPOPT defaults, tol 1e-10
    python3 validation/ipopt/constrained_suite.py chain7 print_level=5 mu_strategy=adaptive
    NSTEPS=50 python3 validation/ipopt/constrained_suite.py cartpole-T2.5-F5

Prints `NAME J=<J> iterations=<n> status=<IPOPT status> J0=<cost of the guess>`.
"""
import os, sys, math, numpy as np, casadi as ca

def natural_spline(ts, ys):
    # returns function giving (y, y', y'') at t for natural cubic spline
    n = len(ts) - 1
    h = np.diff(ts)
    A = np.zeros((n + 1, n + 1)); r = np.zeros(n + 1)
    A[0, 0] = 1; A[n, n] = 1
    for i in range(1, n):
        A[i, i - 1] = h[i - 1]; A[i, i] = 2 * (h[i - 1] + h[i]); A[i, i + 1] = h[i]
        r[i] = 6 * ((ys[i + 1] - ys[i]) / h[i] - (ys[i] - ys[i - 1]) / h[i - 1])
    M = np.linalg.solve(A, r)
    def f(t):
        i = min(max(np.searchsorted(ts, t, side='right') - 1, 0), n - 1)
        a, b = ts[i], ts[i + 1]; hh = b - a
        A_ = (b - t) / hh; B_ = (t - a) / hh
        y = A_ * ys[i] + B_ * ys[i + 1] + ((A_**3 - A_) * M[i] + (B_**3 - B_) * M[i + 1]) * hh * hh / 6
        dy = (ys[i + 1] - ys[i]) / hh + (-(3 * A_**2 - 1) * M[i] + (3 * B_**2 - 1) * M[i + 1]) * hh / 6
        ddy = A_ * M[i] + B_ * M[i + 1]
        return y, dy, ddy
    return f

def smoothstep(q0, qT, T):
    q0 = np.array(q0, float); qT = np.array(qT, float)
    def f(t):
        s = t / T
        return (q0 + (qT - q0) * (3 * s * s - 2 * s**3), (qT - q0) * (6 * s - 6 * s * s) / T, (qT - q0) * (6 - 12 * s) / T**2)
    return f

def double_pendulum_torques(g):
    """The torques (tau_1, tau_2) of the unit double pendulum (examples/common/pendulum.rs,
    tests/planning's DoublePendulum) as a function of (q, q', q'')."""
    def torque(q, v, u):
        c2 = ca.cos(q[1]); m11 = 3 + 2 * c2; m12 = 1 + c2; m22 = 1; b = ca.sin(q[1])
        g1 = 2 * g * ca.sin(q[0]) + g * ca.sin(q[0] + q[1]); g2 = g * ca.sin(q[0] + q[1])
        return (m11 * u[0] + m12 * u[1] - b * (2 * v[0] * v[1] + v[1] ** 2) + g1,
                m12 * u[0] + m22 * u[1] + b * v[0] ** 2 + g2)
    return torque

def problem(name):
    P = {}
    if name.startswith('parking'):
        xbox = float(name.split('x')[1])
        P.update(n=3, T=6.0, q0=[0, 0, 0], qT=[0, 0.5, 0])
        P['L'] = lambda q, v, u: 0.5 * ca.sumsqr(u)
        def mid(q, v, u):
            sp = v[0] * ca.cos(q[2]) + v[1] * ca.sin(q[2])
            return [(v[0] * ca.sin(q[2]) - v[1] * ca.cos(q[2]), 0, 0), (sp * sp - v[2] * v[2], 0, ca.inf), (q[0], -xbox, xbox)]
        P['mid'] = mid
        P['node'] = lambda q, v: [(q[0], -xbox, xbox)]
        wp = [[0, 0, 0], [0.3, 0.1, 0.4], [0.4, 0.25, 0], [0.2, 0.4, -0.4], [0, 0.5, 0]]
        ts = np.array([0, 1.5, 3, 4.5, 6.0])
        sp = [natural_spline(ts, np.array([w[c] for w in wp], float)) for c in range(3)]
        P['guess'] = lambda t: tuple(np.array([sp[c](t)[k] for c in range(3)]) for k in range(3))
    elif name.startswith('chain'):
        n = int(name[5:])
        goal = [1.5] * 3 if n == 3 else [0.5] * 7
        P.update(n=n, T=2.0, q0=[0] * n, qT=goal)
        def L(q, dq, ddq):
            cost = 0; tau = 0
            for r in range(n):
                phi_a = sum(q[i] for i in range(n - r))
                torque = 9.81 * (r + 1) * ca.sin(phi_a)
                for j in range(n - 1 - r, n):
                    for b in range(j + 1):
                        phi_b = sum(q[i] for i in range(b + 1)); dphi_b = sum(dq[i] for i in range(b + 1)); ddphi_b = sum(ddq[i] for i in range(b + 1))
                        d = phi_a - phi_b
                        torque += ca.cos(d) * ddphi_b + ca.sin(d) * dphi_b * dphi_b
                tau += torque
                cost += 0.5 * tau * tau
            return cost
        P['L'] = L
        P['mid'] = lambda q, v, u: [(q[j], -2, 2) for j in range(n)]
        P['node'] = lambda q, v: [(q[j], -2, 2) for j in range(n)]
        P['guess'] = smoothstep(P['q0'], goal, 2.0)
    elif name.startswith('cartpole'):
        _, Ts, Fs = name.split('-'); T = float(Ts[1:]); F = float(Fs[1:])
        mc, mp, l, g = 1.0, 0.3, 0.5, 9.81
        P.update(n=2, T=T, q0=[0, 0], qT=[0, math.pi])
        def forces(q, v, u):
            c = ca.cos(q[1]); s = ca.sin(q[1])
            f = (mc + mp) * u[0] + mp * l * c * u[1] - mp * l * s * v[1]**2
            tp = mp * l * c * u[0] + mp * l * l * u[1] + mp * g * l * s
            return f, tp
        P['L'] = lambda q, v, u: 0.5 * forces(q, v, u)[0]**2
        P['mid'] = lambda q, v, u: [(forces(q, v, u)[1], 0, 0), (forces(q, v, u)[0], -F, F)]
        P['node'] = lambda q, v: []
        P['guess'] = smoothstep(P['q0'], P['qT'], T)
    elif name.startswith('acrobot'):
        # the swing-up suite's acrobot (examples/common/pendulum.rs): the double pendulum with
        # only the elbow actuated, L = 1/2 tau_2^2, the shoulder torque 0 at every step; from
        # the hanging rest to upright rest; `acrobot-T2-zero` starts from the zero path (the
        # failure hunt's guess), `acrobot-T2` from the smoothstep
        T = float(name.split('-')[1][1:]); g = 9.81
        P.update(n=2, T=T, q0=[0, 0], qT=[math.pi, 0])
        torque = double_pendulum_torques(g)
        P['L'] = lambda q, v, u: 0.5 * torque(q, v, u)[1] ** 2
        P['mid'] = lambda q, v, u: [(torque(q, v, u)[0], 0, 0)]
        P['node'] = lambda q, v: []
        if name.endswith('-zero'):
            P['guess'] = lambda t: (np.zeros(2), np.zeros(2), np.zeros(2))
        else:
            P['guess'] = smoothstep(P['q0'], P['qT'], T)
    elif name.startswith('pendulum-tau'):
        # the double pendulum of tests/planning/inequalities.rs: L = 1/2 |tau|^2, the shoulder
        # torque limited by two one-sided rows limit -+ tau_1 >= 0 at the midpoints (as the
        # test's two functions), from the hanging rest to upright rest in T = 2 (NSTEPS=50)
        limit = float(name.split('tau')[1]); g = 9.81
        P.update(n=2, T=2.0, q0=[0, 0], qT=[math.pi, 0])
        torque = double_pendulum_torques(g)
        P['L'] = lambda q, v, u: 0.5 * (torque(q, v, u)[0] ** 2 + torque(q, v, u)[1] ** 2)
        P['mid'] = lambda q, v, u: [(limit - torque(q, v, u)[0], 0, ca.inf), (limit + torque(q, v, u)[0], 0, ca.inf)]
        P['node'] = lambda q, v: []
        P['guess'] = smoothstep(P['q0'], P['qT'], 2.0)
    elif name.startswith('driven'):
        # the weakly controllable system of tests/planning/degenerate.rs: L = 1/2 |u|^2 with
        # the stage equality u_1 - u_0 + c sin q_0 = 0 at the midpoints, from rest at 0 to
        # rest at (1, 1) in T (`driven`: c = 0.3, T = 1; `driven-c0.1-T1`; NSTEPS=100 or 400)
        c, T = 0.3, 1.0
        for part in name.split('-')[1:]:
            if part[0] == 'c': c = float(part[1:])
            if part[0] == 'T': T = float(part[1:])
        P.update(n=2, T=T, q0=[0, 0], qT=[1, 1])
        P['L'] = lambda q, v, u: 0.5 * (u[0] ** 2 + u[1] ** 2)
        P['mid'] = lambda q, v, u: [(u[1] - u[0] + c * ca.sin(q[0]), 0, 0)]
        P['node'] = lambda q, v: []
        P['guess'] = smoothstep(P['q0'], P['qT'], T)
    elif name.startswith('quadrotor'):
        fmax = float(name.split('-f')[1].split('-')[0]); m, I, a, g = 1.0, 0.01, 0.1, 9.81
        P.update(n=3, T=2.0, q0=[0, 0, 0], qT=[2, 1, 0])
        def rot(q, v, u):
            fx = m * u[0]; fz = m * u[1] + m * g; tq = I * u[2]
            s = ca.sin(q[2]); c = ca.cos(q[2])
            Th = -fx * s + fz * c; lat = fx * c + fz * s
            return Th / 2 - tq / (2 * a), Th / 2 + tq / (2 * a), lat
        P['L'] = lambda q, v, u: 0.5 * (rot(q, v, u)[0]**2 + rot(q, v, u)[1]**2)
        disc = lambda q: (q[0] - 1)**2 + (q[1] - 0.5)**2 - 0.09
        P['mid'] = lambda q, v, u: [(rot(q, v, u)[2], 0, 0), (rot(q, v, u)[0], 0, fmax), (rot(q, v, u)[1], 0, fmax), (disc(q), 0, ca.inf)]
        P['node'] = lambda q, v: [(disc(q), 0, ca.inf)]
        if name.endswith('-zero'):
            P['guess'] = lambda t: (np.zeros(3), np.zeros(3), np.zeros(3))
        else:
            P['guess'] = smoothstep(P['q0'], P['qT'], 2.0)
    return P

FORM = 'mid'
ENDS = 'fixed'
ENDGUESS = 'data'
def end_guess(P, t, fixed):
    """The first value of an end variable (ends=eq): its fixed data, or with endguess=curve
    the guess curve's jet at t (the suite's splines leave the ends moving: the earlier
    reference's start, which gave parking-x0.4 6.3847853 in 68 iterations)."""
    if ENDGUESS == 'curve':
        q, v, _ = P['guess'](t)
        return list(q) + list(v)
    return list(fixed)

def solve(name, opts, nodebounds):
    P = problem(name); n = P['n']; T = P['T']; N = int(os.environ.get('NSTEPS', round(100 * T))); h = T / N
    x0 = np.concatenate([P['q0'], np.zeros(n)]); xN = np.concatenate([P['qT'], np.zeros(n)])
    w = []; lbw = []; ubw = []; w0 = []
    g = []; lbg = []; ubg = []
    X = [ca.DM(x0)]
    if ENDS == 'eq':
        # the fixed ends as variables held by equality constraints
        X = [ca.SX.sym('x0', 2 * n)]
        w.append(X[0]); w0 += end_guess(P, 0.0, x0); lbw += [-ca.inf] * (2 * n); ubw += [ca.inf] * (2 * n)
        g.append(X[0] - ca.DM(x0)); lbg += [0] * (2 * n); ubg += [0] * (2 * n)
    for i in range(1, N):
        xi = ca.SX.sym('x%d' % i, 2 * n); X.append(xi)
    if ENDS == 'eq':
        X.append(ca.SX.sym('xN', 2 * n))
        w.append(X[N]); w0 += end_guess(P, T, xN); lbw += [-ca.inf] * (2 * n); ubw += [ca.inf] * (2 * n)
        g.append(X[N] - ca.DM(xN)); lbg += [0] * (2 * n); ubg += [0] * (2 * n)
    else:
        X.append(ca.DM(xN))
    U = [ca.SX.sym('u%d' % i, n) for i in range(N)]
    J = 0
    for i in range(1, N):
        t = i * h; q, v, _ = P['guess'](t)
        w.append(X[i]); w0 += list(q) + list(v)
        lo = [-ca.inf] * (2 * n); hi = [ca.inf] * (2 * n)
        nodes = P['node'](X[i][:n], X[i][n:])
        if nodebounds == 'var':
            for (expr, l, u) in nodes:
                # expr is a component of q: find index
                k = [j for j in range(n) if ca.is_equal(expr, X[i][j])]
                if k: lo[k[0]] = l; hi[k[0]] = u
                else:
                    g.append(expr); lbg.append(l); ubg.append(u)
        else:
            for (expr, l, u) in nodes:
                g.append(expr); lbg.append(l); ubg.append(u)
        lbw += lo; ubw += hi
    for i in range(N):
        t = (i + 0.5) * h; _, _, a = P['guess'](t)
        w.append(U[i]); w0 += list(a); lbw += [-ca.inf] * n; ubw += [ca.inf] * n
    for i in range(N):
        xm = (X[i] + X[i + 1]) / 2; q = xm[:n]; v = xm[n:]
        if FORM == 'next':
            g.append(X[i + 1][:n] - X[i][:n] - h * X[i][n:] - h * h / 2 * U[i]); lbg += [0] * n; ubg += [0] * n
        else:
            g.append(X[i + 1][:n] - X[i][:n] - h * v); lbg += [0] * n; ubg += [0] * n
        g.append(X[i + 1][n:] - X[i][n:] - h * U[i]); lbg += [0] * n; ubg += [0] * n
        for (expr, l, u) in P['mid'](q, v, U[i]):
            g.append(expr); lbg.append(l); ubg.append(u)
        J += h * P['L'](q, v, U[i])
    nlp = {'x': ca.vertcat(*w), 'f': J, 'g': ca.vertcat(*g)}
    o = {'ipopt.tol': 1e-10, 'print_time': False, 'ipopt.print_level': 0, 'ipopt.sb': 'yes'}
    for k, val in opts.items(): o['ipopt.' + k] = val
    S = ca.nlpsol('S', 'ipopt', nlp, o)
    r = S(x0=w0, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
    st = S.stats()
    J0 = float(ca.Function('f', [nlp['x']], [J])(w0))
    print('%s J=%.10f iterations=%d status=%s J0=%.10e' % (name, float(r['f']), st['iter_count'], st['return_status'], J0), flush=True)

if __name__ == '__main__':
    names = sys.argv[1]

    opts = {}; nb = 'g'
    for a in sys.argv[2:]:
        k, v = a.split('=')
        if k == 'nodebounds': nb = v; continue
        if k == 'form': globals()['FORM'] = v; continue
        if k == 'ends': globals()['ENDS'] = v; continue
        if k == 'endguess': globals()['ENDGUESS'] = v; continue
        for cv in (int, float):
            try: v = cv(v); break
            except ValueError: pass
        opts[k] = v
    allp = ['cartpole-T2-F12', 'cartpole-T2-F10', 'cartpole-T3-F6', 'quadrotor-f15', 'quadrotor-f6', 'parking-x0.8', 'parking-x0.4', 'chain3', 'chain7']
    for name in (allp if names == 'all' else names.split(',')):
        solve(name, opts, nb)
