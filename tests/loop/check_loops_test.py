#!/usr/bin/env python3
"""tests/loop/check_loops.py --odometry against known numbers: a log with three ground-truth poses,
a loop and an odometry each off the truth's relative pose by a planted right perturbation; the
script must print those perturbations and the NEES of the loop's with its information."""
import json, math, os, re, struct, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_loops as cl  # noqa: E402


def exp_q(v):
    a = math.sqrt(sum(x*x for x in v))
    if a < 1e-15:
        return (1.0, 0.0, 0.0, 0.0)
    s = math.sin(a / 2) / a
    return (math.cos(a / 2), v[0]*s, v[1]*s, v[2]*s)


def perturbed(q, t, xi):
    """(R Exp(phi), t + R tau)."""
    return cl.qmul(q, exp_q(xi[:3])), tuple(t[i] + cl.qrot(q, xi[3:])[i] for i in range(3))


def ground_truth_event(utime, p, q):
    name = b"world"
    payload = struct.pack(">q", 0) + struct.pack(">q", utime)
    payload += struct.pack(">i", len(name)) + name + struct.pack(">i", len(name)) + name
    payload += struct.pack(">3d", *p) + struct.pack(">4d", *q)
    ch = b"GROUND_TRUTH"
    return struct.pack(">IqqII", 0xEDA1DA01, 0, utime, len(ch), len(payload)) + ch + payload


def main():
    failures = []
    # right_error recovers a planted perturbation exactly (to rounding)
    q0, t0 = exp_q((0.3, -0.2, 1.1)), (1.0, -2.0, 0.5)
    xi = [0.01, -0.004, 0.02, 0.05, -0.03, 0.07]
    q1, t1 = perturbed(q0, t0, xi)
    got = cl.right_error(q0, t0, q1, t1)
    if max(abs(g - x) for g, x in zip(got, xi)) > 1e-12:
        failures.append("right_error %s, planted %s" % (got, xi))

    # the whole script on a log: truth at t = 0, 1, 2 s; a loop 2 -> 0 and an odometry off it
    gt = [(0.0, (0.0, 0.0, 0.0), exp_q((0, 0, 0.2))), (1.0, (3.0, 1.0, 0.0), exp_q((0, 0, 1.5))),
          (2.0, (0.5, 4.0, 0.1), exp_q((0.01, 0, 3.0)))]
    q_to, t_to = gt[0][2], gt[0][1]
    q_from, t_from = gt[2][2], gt[2][1]
    q_rel = cl.qmul(cl.qconj(q_to), q_from)
    t_rel = cl.qrot(cl.qconj(q_to), tuple(t_from[i] - t_to[i] for i in range(3)))
    loop_xi = [0.002, -0.001, 0.0005, 0.03, -0.01, 0.02]   # the truth off the loop by this
    odo_xi = [-0.004, 0.003, 0.001, -0.02, 0.015, 0.005]  # and off the odometry by this
    # T_true = T_loop (R Exp(phi), t + R tau): the loop is the truth perturbed by the inverse
    q_loop = cl.qmul(q_rel, exp_q([-x for x in loop_xi[:3]]))
    t_loop = tuple(t_rel[i] - cl.qrot(q_loop, loop_xi[3:])[i] for i in range(3))
    info = [0.0] * 36
    for i, s in enumerate([0.01, 0.01, 0.002, 0.02, 0.02, 0.01]):
        info[7 * i] = 1.0 / (s * s)
    nees = sum(loop_xi[i] ** 2 * info[7 * i] for i in range(6))
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "sim.lcmlog"), "wb") as f:
            for t, p, q in gt:
                f.write(ground_truth_event(int(t * 1e6), p, q))
        loops = {"num_keyframes": 3, "loops": [{
            "from_id": 2, "to_id": 0, "from_time": 2.0, "to_time": 0.0, "coarse_inliers": 20, "fitness": 0.1,
            "overlap": 0.9, "corrected": True, "information": info,
            "T_to_from": {"rotation_wxyz": list(q_loop), "translation": list(t_loop)}}]}
        json.dump(loops, open(os.path.join(d, "loops.json"), "w"))
        # an odometry whose relative pose 0 -> 2 is the truth's with odo_xi taken out likewise
        q_o = cl.qmul(q_rel, exp_q([-x for x in odo_xi[:3]]))
        t_o = tuple(t_rel[i] - cl.qrot(q_o, odo_xi[3:])[i] for i in range(3))
        with open(os.path.join(d, "odometry.tum"), "w") as f:
            for t, p, q in ((0.0, (0, 0, 0), (1, 0, 0, 0)), (1.0, (1, 1, 0), (1, 0, 0, 0)), (2.0, t_o, q_o)):
                f.write("%.6f %.12f %.12f %.12f %.15f %.15f %.15f %.15f\n" % (t, p[0], p[1], p[2], q[1], q[2], q[3], q[0]))
        out = subprocess.run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_loops.py"),
                              "--log", os.path.join(d, "sim.lcmlog"), "--loops", os.path.join(d, "loops.json"),
                              "--odometry", os.path.join(d, "odometry.tum")], capture_output=True, text=True)
    print(out.stdout, end="")
    if out.returncode != 0:
        failures.append("exit %d: %s" % (out.returncode, out.stderr))
    m = re.search(r"loop rot \[(.*)\] deg  trans \[(.*)\] m  NEES ([0-9.]+)", out.stdout)
    o = re.search(r"odom rot \[(.*)\] deg  trans \[(.*)\] m", out.stdout)
    if not m or not o:
        failures.append("no --odometry lines")
    else:
        def parsed(g):
            return [math.radians(float(x)) for x in g.group(1).split()] + [float(x) for x in g.group(2).split()]
        for what, got, want in (("loop", parsed(m), loop_xi), ("odometry", parsed(o), odo_xi)):
            if max(abs(g - w) for g, w in zip(got, want)) > 2e-4:  # printed to 1e-3 deg, 1e-4 m
                failures.append("%s error %s, planted %s" % (what, got, want))
        if abs(float(m.group(3)) - nees) > 0.05 + 1e-3 * nees:
            failures.append("NEES %s, planted %.2f" % (m.group(3), nees))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
