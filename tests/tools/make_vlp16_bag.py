#!/usr/bin/python3
"""Writes a ROS 1 bag of a hand-held walk through a textured room, as a Velodyne VLP-16, an IMU and
a colour camera with a CameraInfo would record it, with the body's ground truth. Written from
scratch with Debian's python3-rosbag and numpy, independent of livo-sim and of anything else in
this repository, so that the bag -> report path (scripts/run_bag.sh) is tested on data the
project's own simulator did not make.

The rig is exactly the nominal one of config/rigs/template_velodyne_vlp16.yaml, so that file runs
the bag unedited:
  IMU      body frame = IMU frame; 200 Hz; white noise at the template's placeholder densities
           (gyro 2.4e-4 rad/s/sqrt(Hz), accel 1.7e-3 m/s^2/sqrt(Hz)) and a small constant bias
           (gyro 2 mrad/s, accel 0.03 m/s^2 per axis, 1 sigma, drawn from the seed); gravity 9.81.
  LiDAR    VLP-16, 10 cm above the IMU, axes aligned (T_I_L translation [0, 0, 0.1]); 16 beams at
           -15 .. +15 deg every 2 deg (firing order -15, 1, -13, 3, ...; ring 0 = lowest), 1800
           columns of 0.2 deg per turn, 10 Hz, turning clockwise seen from above, each laser fired
           2.304 us after the previous one; every point is measured from the sensor's pose at its own
           time (real motion distortion) with Gaussian range noise of 3 cm (the template's
           range_noise_std). sensor_msgs/PointCloud2 as the velodyne_pointcloud driver writes it:
           x y z intensity (float32) ring (uint16) time (float32, seconds after the header stamp,
           which is the sweep start), packed, 22 bytes per point.
  Camera   640x480, fx = fy = 500, cx = 319.5, cy = 239.5, no distortion, 20 Hz, colour, global
           shutter, at the body origin looking along the body's x (T_I_C rpy [-90, 0, -90]);
           sensor_msgs/CompressedImage PNG (rgb8, written with zlib: no imaging package needed)
           and a sensor_msgs/CameraInfo (plumb_bob) with each image.
  Truth    geometry_msgs/PoseStamped of the IMU body in the world (z up) at 100 Hz.

Scene: a closed 20 x 12 x 3.5 m room with boxes (some turned about z) and floor-to-ceiling
pillars; every surface carries a mosaic of high-contrast colour tiles (0.2-0.45 m, a different
size per surface) under smooth lighting, so a direct photometric VIO finds gradients, rendered by
ray casting with each pixel's footprint filtered at tile edges. The LiDAR intensity is the
surface's brightness. Not modelled: image noise, exposure changes, blur and rolling shutter, LiDAR
dropouts and per-beam origin offsets, clock offsets between the sensors (all share one clock).
Motion: at rest for 2 s, a 2 s smooth start, then a walk around an ellipse (6 x 3.2 m half axes,
one lap in 25 s: back at the start at about 28 s) with the view swinging +-20 deg about the
direction of travel, a slow 0.2 m rise and fall, a 1.8 Hz step bob and sway, and small pitch and
roll; position and Euler angles are sums of sinusoids of a smoothly started time, so velocity,
acceleration and angular rate are exact derivatives (checked at start-up against finite
differences). The scene and the path are fixed; the seed draws the noise and the biases, so a
seed gives the same bag every time.

Topics: /imu/data, /velodyne_points, /camera/image_raw/compressed, /camera/camera_info,
/ground_truth/pose. Import with
  build/bin/livo-import rosbag OUT.bag --ground-truth /ground_truth/pose --out OUT.lcmlog
or run it with scripts/run_bag.sh OUT.bag --rig config/rigs/template_velodyne_vlp16.yaml
--ground-truth /ground_truth/pose --out DIR.

usage: make_vlp16_bag.py OUT.bag [--duration S] [--seed N]
"""
import argparse
import math
import struct
import sys
import time
import zlib

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo, CompressedImage, Imu, PointCloud2, PointField

# ---- the rig (config/rigs/template_velodyne_vlp16.yaml, nominal) -------------------------------
GRAVITY = 9.81
IMU_RATE = 200.0
GYRO_NOISE_DENSITY = 2.4e-4   # rad/s/sqrt(Hz)
ACCEL_NOISE_DENSITY = 1.7e-3  # m/s^2/sqrt(Hz)
GYRO_BIAS_STD = 0.002         # rad/s
ACCEL_BIAS_STD = 0.03         # m/s^2
LIDAR_IN_BODY = np.array([0.0, 0.0, 0.1])
LIDAR_RATE = 10.0
COLUMNS = 1800                # 0.2 deg
FIRING_ELEVATIONS_DEG = [-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15]
LASER_INTERVAL = 2.304e-6     # s between two lasers of a firing sequence
RANGE_NOISE = 0.03            # m
MIN_RANGE, MAX_RANGE = 0.5, 100.0
WIDTH, HEIGHT, FX, FY, CX, CY = 640, 480, 500.0, 500.0, 319.5, 239.5
CAMERA_RATE = 20.0
CAMERA_PHASE = 0.0125         # s: the camera runs free of the LiDAR
GROUND_TRUTH_RATE = 100.0
BAG_START = 1700000000        # s, ROS time of the first instant


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


R_I_C = rot_z(-math.pi / 2) @ rot_x(-math.pi / 2)  # rpy_deg [-90, 0, -90]: camera z = body x


# ---- the motion -------------------------------------------------------------------------------
class Signal:
    """c0 + c1 u + sum A sin(w u + phi), with its first and second derivatives in u."""

    def __init__(self, c0, c1=0.0, terms=()):
        self.c0, self.c1, self.terms = c0, c1, terms

    def __call__(self, u):
        f = self.c0 + self.c1 * u
        d1 = self.c1 + 0.0 * u
        d2 = 0.0 * u
        for a, w, phi in self.terms:
            s, c = np.sin(w * u + phi), np.cos(w * u + phi)
            f = f + a * s
            d1 = d1 + a * w * c
            d2 = d2 - a * w * w * s
        return f, d1, d2


class Trajectory:
    REST = 2.0    # s at rest
    RAMP = 2.0    # s of smooth start
    LAP = 25.0    # s per lap of the ellipse at full pace
    A, B = 6.0, 3.2
    STEP = 2 * math.pi * 1.8  # rad/s: the step bob

    def __init__(self):
        om = 2 * math.pi / self.LAP
        th0 = -math.pi / 2  # start at (0, -3.2), walking along +x
        s = self.STEP
        self.x = Signal(0.0, 0.0, ((self.A, om, th0 + math.pi / 2), (0.03, s / 2, 0.4)))
        self.y = Signal(0.0, 0.0, ((self.B, om, th0), (0.03, s / 2, 1.9)))
        self.z = Signal(1.35, 0.0, ((0.2, 0.5, 0.0), (0.02, s, 0.2)))
        self.yaw = Signal(th0 + math.pi / 2, om, ((0.3, 0.8, 0.0), (0.06, 2.3, 1.0)))
        self.pitch = Signal(0.0, 0.0, ((0.08, 0.6, 0.3), (0.02, s, 0.9)))
        self.roll = Signal(0.0, 0.0, ((0.06, 0.45, 1.2), (0.02, s / 2, 0.7)))

    def warp(self, t):
        """Motion time u(t) with u' and u'': 0 at rest, then a smootherstep start to u' = 1."""
        x = np.clip((t - self.REST) / self.RAMP, 0.0, 1.0)
        u = self.RAMP * (x ** 6 - 3 * x ** 5 + 2.5 * x ** 4) + np.maximum(t - self.REST - self.RAMP, 0.0)
        du = 6 * x ** 5 - 15 * x ** 4 + 10 * x ** 3
        ddu = (30 * x ** 4 - 60 * x ** 3 + 30 * x ** 2) / self.RAMP
        return u, du, ddu

    def state(self, t):
        """Position p, acceleration a (world), rotation R_W_I and body angular rate w_I at times t (N)."""
        t = np.asarray(t, dtype=np.float64)
        u, du, ddu = self.warp(t)

        def timed(sig):  # value, d/dt, d2/dt2
            f, f1, f2 = sig(u)
            return f, f1 * du, f2 * du * du + f1 * ddu

        (x, _, ax), (y, _, ay), (z, _, az) = timed(self.x), timed(self.y), timed(self.z)
        (yaw, dyaw, _), (pitch, dpitch, _), (roll, droll, _) = timed(self.yaw), timed(self.pitch), timed(self.roll)
        p = np.stack([x, y, z], axis=-1)
        a = np.stack([ax, ay, az], axis=-1)
        R = euler_zyx(yaw, pitch, roll)
        cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
        w = np.stack([droll - dyaw * sp, dpitch * cr + dyaw * sr * cp, -dpitch * sr + dyaw * cr * cp], axis=-1)
        return p, a, R, w, (yaw, pitch, roll)


def euler_zyx(yaw, pitch, roll):
    """R = Rz(yaw) Ry(pitch) Rx(roll), shape (N, 3, 3)."""
    cy, sy, cp, sp, cr, sr = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch), np.cos(roll), np.sin(roll)
    return np.stack([np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
                     np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
                     np.stack([-sp, cp * sr, cp * cr], -1)], -2)


def check_derivatives(traj):
    """The analytic acceleration and body rate against central differences of position and rotation."""
    t = np.array([1.0, 2.7, 3.3, 5.0, 11.1, 17.6, 24.9])
    h = 1e-4
    p0, a0, R0, w0, _ = traj.state(t)
    pp, _, Rp, _, _ = traj.state(t + h)
    pm, _, Rm, _, _ = traj.state(t - h)
    a_num = (pp - 2 * p0 + pm) / (h * h)
    dR = np.einsum('nji,njk->nik', R0, (Rp - Rm) / (2 * h))  # R^T dR/dt = [w]x
    w_num = np.stack([dR[:, 2, 1], dR[:, 0, 2], dR[:, 1, 0]], axis=-1)
    assert np.abs(a_num - a0).max() < 1e-3, ('acceleration', np.abs(a_num - a0).max())
    assert np.abs(w_num - w0).max() < 1e-6, ('angular rate', np.abs(w_num - w0).max())


def quaternion_zyx(yaw, pitch, roll):
    """(x, y, z, w) of Rz(yaw) Ry(pitch) Rx(roll)."""
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


# ---- the scene --------------------------------------------------------------------------------
ROOM_LO = np.array([-10.0, -6.0, 0.0])
ROOM_HI = np.array([10.0, 6.0, 3.5])
# boxes standing on the floor: centre x, y, half extents x, y, z (height = 2 hz), yaw in degrees
BOXES = [(0.0, 0.0, 2.5, 0.6, 0.75, 0.0),
         (-3.2, 0.8, 0.5, 0.5, 1.0, 30.0),
         (7.5, 4.5, 1.0, 0.6, 0.9, 0.0),
         (-7.8, -4.4, 0.8, 0.8, 1.2, 20.0),
         (0.5, 5.0, 1.5, 0.5, 0.6, 0.0),
         (-1.0, -5.1, 1.2, 0.4, 1.6, 0.0),
         (8.6, -1.0, 0.6, 1.4, 0.5, -15.0)]
PILLARS = [(3.5, -0.5, 0.3), (-6.5, 3.8, 0.25), (6.8, -3.6, 0.25)]  # floor to ceiling: x, y, radius
LIGHTS = np.array([[-5.0, -2.0, 3.5], [4.0, 2.5, 3.5], [0.0, -5.5, 2.0]], np.float32)
PALETTE = np.array([[230, 57, 70], [241, 250, 238], [29, 53, 87], [252, 191, 73], [42, 157, 143], [38, 70, 83],
                    [244, 162, 97], [20, 20, 24], [131, 56, 236], [255, 255, 255], [58, 134, 255], [6, 214, 160],
                    [120, 120, 120], [255, 0, 110], [45, 106, 79], [200, 200, 60]], dtype=np.float32) / 255.0
NO_HIT = np.float32(1e9)


class Scene:
    """Ray casting against the room (inside of a box), boxes (slabs in the box's frame) and
    vertical cylinders; surfaces are numbered, each with a tile size and its own tile colours."""

    def __init__(self):
        self.boxes = []
        for cx, cy, hx, hy, hz, yaw in BOXES:
            R = rot_z(math.radians(yaw)).astype(np.float32)
            self.boxes.append((np.array([cx, cy, hz], np.float32), np.array([hx, hy, hz], np.float32), R))
        self.surfaces = 6 + 6 * len(self.boxes) + len(PILLARS)
        rng = np.random.default_rng(12345)  # the scene is fixed, whatever the bag's seed
        self.tile = rng.uniform(0.2, 0.45, self.surfaces).astype(np.float32)
        self.salt = rng.integers(1, 2 ** 31 - 1, self.surfaces).astype(np.uint32)

    def cast(self, o, d):
        """Distance along d (unit rows, (N, 3)) from o ((3,) or (N, 3)) to the first hit, and the
        primitive hit: 0 room, 1 + i box i, 1 + len(boxes) + j pillar j."""
        o = np.asarray(o, np.float32)
        ox, oy, oz = o[..., 0], o[..., 1], o[..., 2]
        dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
        with np.errstate(divide='ignore', invalid='ignore'):
            best = np.full(d.shape[0], NO_HIT, np.float32)
            for k, (oc, dc) in enumerate(((ox, dx), (oy, dy), (oz, dz))):  # the room, from inside
                t = (np.where(dc > 0, ROOM_HI[k], ROOM_LO[k]).astype(np.float32) - oc) / dc
                best = np.minimum(best, np.where(np.isfinite(t) & (t > 0), t, NO_HIT))
            prim = np.zeros(d.shape[0], np.int16)
            for i, (c, h, R) in enumerate(self.boxes):
                # into the box's frame (a turn about z): local = R^T (x - c)
                rx, ry = ox - c[0], oy - c[1]
                lox, loy, loz = R[0, 0] * rx + R[1, 0] * ry, R[0, 1] * rx + R[1, 1] * ry, oz - c[2]
                ldx, ldy = R[0, 0] * dx + R[1, 0] * dy, R[0, 1] * dx + R[1, 1] * dy
                tmin = np.full(d.shape[0], -NO_HIT, np.float32)
                tmax = np.full(d.shape[0], NO_HIT, np.float32)
                for lo_, ld, hk in ((lox, ldx, h[0]), (loy, ldy, h[1]), (loz, dz, h[2])):
                    inv = 1.0 / ld
                    t1, t2 = (-hk - lo_) * inv, (hk - lo_) * inv
                    tmin = np.maximum(tmin, np.minimum(t1, t2))
                    tmax = np.minimum(tmax, np.maximum(t1, t2))
                hit = (tmax >= tmin) & (tmin > 1e-4) & (tmin < best)
                best = np.where(hit, tmin, best)
                prim[hit] = 1 + i
            for j, (px, py, r) in enumerate(PILLARS):
                rx, ry = ox - px, oy - py
                a = dx * dx + dy * dy
                b = rx * dx + ry * dy
                c = rx * rx + ry * ry - r * r
                disc = b * b - a * c
                t = (-b - np.sqrt(np.maximum(disc, 0))) / a
                hit = (disc > 0) & (t > 1e-4) & (t < best)
                best = np.where(hit, t, best)
                prim[hit] = 1 + len(self.boxes) + j
        return best, prim

    def surface(self, p, prim):
        """Surface number, in-surface coordinates (metres) and unit normal of hit points p (N, 3)."""
        n = p.shape[0]
        sid = np.zeros(n, np.int32)
        s = np.zeros(n, np.float32)
        v = np.zeros(n, np.float32)
        normal = np.zeros((n, 3), np.float32)
        m = prim == 0
        if m.any():
            q = p[m]
            gap = np.concatenate([q - ROOM_LO, ROOM_HI - q], axis=1)  # distance to each of the six faces
            f = np.argmin(gap, axis=1)
            axis = f % 3
            sid[m] = f
            s[m] = np.where(axis == 0, q[:, 1], q[:, 0])
            v[m] = np.where(axis == 2, q[:, 1], q[:, 2])
            normal[np.flatnonzero(m), axis] = 1.0
        for i, (c, h, R) in enumerate(self.boxes):
            m = prim == 1 + i
            if not m.any():
                continue
            q = (p[m] - c) @ R  # local
            f = np.argmax(np.abs(q) / h, axis=1)
            side = (np.take_along_axis(q, f[:, None], 1)[:, 0] > 0).astype(np.int32)
            sid[m] = 6 + 6 * i + 2 * f + side
            s[m] = np.where(f == 0, q[:, 1], q[:, 0])
            v[m] = np.where(f == 2, q[:, 1], q[:, 2])
            normal[m] = R.T[f]  # the box's axis f in the world (sign irrelevant here)
        for j, (px, py, r) in enumerate(PILLARS):
            m = prim == 1 + len(self.boxes) + j
            if not m.any():
                continue
            q = p[m]
            sid[m] = 6 + 6 * len(self.boxes) + j
            s[m] = r * np.arctan2(q[:, 1] - py, q[:, 0] - px)
            v[m] = q[:, 2]
            normal[m, 0], normal[m, 1] = (q[:, 0] - px) / r, (q[:, 1] - py) / r
        return sid, s, v, normal

    def tile_colour(self, sid, i, j):
        h = (i.astype(np.int64) * 73856093 ^ j.astype(np.int64) * 19349663).astype(np.uint32) ^ self.salt[sid]
        h = (h * np.uint32(2654435761)) >> np.uint32(16)
        return PALETTE[h % len(PALETTE)]

    def colour(self, p, sid, s, v, footprint=None):
        """RGB in [0, 1] of hit points on surfaces `sid` at (s, v): tiles (box-filtered over
        `footprint` metres at their edges) under smooth lighting."""
        tile = self.tile[sid]
        x, y = s / tile, v / tile
        i, j = np.floor(x), np.floor(y)
        fx, fy = x - i, y - j
        rgb = self.tile_colour(sid, i, j)
        if footprint is not None:  # blend with the neighbour tile across the nearest edges
            w = np.maximum(footprint / tile, 1e-3)
            wx = np.clip(0.5 - np.minimum(fx, 1 - fx) / w, 0, 0.5)
            wy = np.clip(0.5 - np.minimum(fy, 1 - fy) / w, 0, 0.5)
            e = np.flatnonzero((wx > 0) | (wy > 0))  # pixels whose footprint crosses an edge
            se, ie, je, wx, wy = sid[e], i[e], j[e], wx[e, None], wy[e, None]
            ni, nj = np.where(fx[e] > 0.5, ie + 1, ie - 1), np.where(fy[e] > 0.5, je + 1, je - 1)
            rgb[e] = ((1 - wx) * (1 - wy) * rgb[e] + wx * (1 - wy) * self.tile_colour(se, ni, je) +
                      (1 - wx) * wy * self.tile_colour(se, ie, nj) + wx * wy * self.tile_colour(se, ni, nj))
        light = np.full(p.shape[0], 0.55, np.float32)
        for L in LIGHTS:
            light += 0.45 * np.exp(-np.sum((p - L) ** 2, axis=1) / 40.0)
        return rgb * np.minimum(light, 1.0)[:, None]


# ---- sensors ----------------------------------------------------------------------------------
def stamp(t):
    ns = BAG_START * 10 ** 9 + int(round(t * 1e9))
    return rospy.Time(ns // 10 ** 9, ns % 10 ** 9)


def png_rgb(img):
    """PNG bytes of an (H, W, 3) uint8 image (each row 'Sub'-filtered: tiles compress to runs)."""
    h, w, _ = img.shape
    rows = img.reshape(h, w * 3)
    sub = rows.copy()
    sub[:, 3:] = rows[:, 3:] - rows[:, :-3]  # uint8 arithmetic wraps, as the filter wants
    raw = np.concatenate([np.ones((h, 1), np.uint8), sub], axis=1).tobytes()

    def chunk(tag, data):
        return struct.pack('>I', len(data)) + tag + data + struct.pack('>I', zlib.crc32(tag + data) & 0xffffffff)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw, 3)) + chunk(b'IEND', b''))


class Camera:
    def __init__(self, scene):
        self.scene = scene
        u, v = np.meshgrid(np.arange(WIDTH, dtype=np.float32), np.arange(HEIGHT, dtype=np.float32))
        d = np.stack([(u - CX) / FX, (v - CY) / FY, np.ones_like(u)], axis=-1).reshape(-1, 3)
        self.norm = np.linalg.norm(d, axis=1)
        self.rays = (d / self.norm[:, None]).astype(np.float32)  # camera frame, unit

    def render(self, p_W_I, R_W_I):
        R_W_C = (R_W_I @ R_I_C).astype(np.float32)
        d = self.rays @ R_W_C.T
        t, prim = self.scene.cast(p_W_I, d)
        hit = p_W_I.astype(np.float32) + t[:, None] * d
        sid, s, v, normal = self.scene.surface(hit, prim)
        # a pixel's footprint on the surface: its angle times the distance, over the incidence
        incidence = np.abs(np.sum(normal * d, axis=1))
        footprint = t * (1.0 / FX) * self.norm ** -2 / np.maximum(incidence, 0.25)
        rgb = self.scene.colour(hit, sid, s, v, footprint)
        return np.clip(rgb * 255.0 + 0.5, 0, 255).astype(np.uint8).reshape(HEIGHT, WIDTH, 3)

    def messages(self, t, p_W_I, R_W_I):
        img = CompressedImage()
        img.header.stamp = stamp(t)
        img.header.frame_id = 'camera'
        img.format = 'rgb8; png compressed rgb8'
        img.data = png_rgb(self.render(p_W_I, R_W_I))
        info = CameraInfo()
        info.header = img.header
        info.width, info.height = WIDTH, HEIGHT
        info.distortion_model = 'plumb_bob'
        info.D = [0.0, 0.0, 0.0, 0.0, 0.0]
        info.K = [FX, 0.0, CX, 0.0, FY, CY, 0.0, 0.0, 1.0]
        info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        info.P = [FX, 0.0, CX, 0.0, 0.0, FY, CY, 0.0, 0.0, 0.0, 1.0, 0.0]
        return img, info


POINT_DTYPE = np.dtype([('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('intensity', '<f4'), ('ring', '<u2'),
                        ('time', '<f4')])  # packed: 22 bytes, as velodyne_pointcloud's PointXYZIRT fields


class Lidar:
    def __init__(self, scene, traj, rng):
        self.scene, self.traj, self.rng = scene, traj, rng
        elev = np.radians(np.array(FIRING_ELEVATIONS_DEG, np.float64))
        azim = math.pi - 2 * math.pi * np.arange(COLUMNS) / COLUMNS  # clockwise from behind
        e, a = np.meshgrid(elev, azim)  # (columns, lasers)
        self.dirs = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], axis=-1).reshape(-1, 3)
        self.ring = ((np.array(FIRING_ELEVATIONS_DEG) + 15) // 2).astype(np.uint16)
        self.ring = np.tile(self.ring, COLUMNS)
        column_time = np.arange(COLUMNS) / COLUMNS / LIDAR_RATE
        self.offset = (column_time[:, None] + np.arange(16)[None, :] * LASER_INTERVAL).reshape(-1)

    def cloud(self, t0):
        p, _, R, _, _ = self.traj.state(t0 + self.offset)
        origin = p + R @ LIDAR_IN_BODY
        d = np.einsum('nij,nj->ni', R, self.dirs).astype(np.float32)
        r, prim = self.scene.cast(origin.astype(np.float32), d)
        hit = origin.astype(np.float32) + r[:, None] * d
        sid, s, v, _ = self.scene.surface(hit, prim)
        intensity = 255.0 * np.mean(self.scene.colour(hit, sid, s, v), axis=1)
        measured = r + self.rng.normal(0.0, RANGE_NOISE, r.shape)
        keep = (measured > MIN_RANGE) & (measured < MAX_RANGE) & (r < NO_HIT)
        pts = np.zeros(int(keep.sum()), POINT_DTYPE)
        xyz = self.dirs[keep] * measured[keep, None]  # the point in the LiDAR frame at its own time
        pts['x'], pts['y'], pts['z'] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
        pts['intensity'] = intensity[keep]
        pts['ring'] = self.ring[keep]
        pts['time'] = self.offset[keep]
        msg = PointCloud2()
        msg.header.stamp = stamp(t0)
        msg.header.frame_id = 'velodyne'
        msg.height, msg.width = 1, len(pts)
        f = PointField
        msg.fields = [f('x', 0, f.FLOAT32, 1), f('y', 4, f.FLOAT32, 1), f('z', 8, f.FLOAT32, 1),
                      f('intensity', 12, f.FLOAT32, 1), f('ring', 16, f.UINT16, 1), f('time', 18, f.FLOAT32, 1)]
        msg.is_bigendian = False
        msg.point_step = POINT_DTYPE.itemsize
        msg.row_step = msg.point_step * msg.width
        msg.data = pts.tobytes()
        msg.is_dense = True
        return msg


def imu_messages(traj, duration, rng):
    n = int(round(duration * IMU_RATE))
    t = np.arange(n) / IMU_RATE
    _, a, R, w, _ = traj.state(t)
    f = np.einsum('nji,nj->ni', R, a + np.array([0.0, 0.0, GRAVITY]))  # specific force in the body
    gyro_bias = rng.normal(0.0, GYRO_BIAS_STD, 3)
    accel_bias = rng.normal(0.0, ACCEL_BIAS_STD, 3)
    gyro = w + gyro_bias + rng.normal(0.0, GYRO_NOISE_DENSITY * math.sqrt(IMU_RATE), w.shape)
    accel = f + accel_bias + rng.normal(0.0, ACCEL_NOISE_DENSITY * math.sqrt(IMU_RATE), f.shape)
    for k in range(n):
        m = Imu()
        m.header.stamp = stamp(t[k])
        m.header.frame_id = 'imu_link'
        m.orientation_covariance[0] = -1.0  # no orientation
        m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = gyro[k]
        m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = accel[k]
        yield t[k], m
    print('IMU biases: gyro %s rad/s, accel %s m/s^2' % (np.round(gyro_bias, 5), np.round(accel_bias, 4)),
          file=sys.stderr)


def ground_truth_messages(traj, duration):
    n = int(round(duration * GROUND_TRUTH_RATE))
    t = np.arange(n) / GROUND_TRUTH_RATE
    p, _, _, _, (yaw, pitch, roll) = traj.state(t)
    for k in range(n):
        m = PoseStamped()
        m.header.stamp = stamp(t[k])
        m.header.frame_id = 'world'
        m.pose.position.x, m.pose.position.y, m.pose.position.z = p[k]
        q = quaternion_zyx(yaw[k], pitch[k], roll[k])
        m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w = q
        yield t[k], m


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('out', help='the bag to write')
    ap.add_argument('--duration', type=float, default=30.0, help='seconds (default 30)')
    ap.add_argument('--seed', type=int, default=1, help='noise and biases (default 1)')
    args = ap.parse_args()
    if args.duration <= 0:
        ap.error('--duration must be > 0')
    traj = Trajectory()
    check_derivatives(traj)
    scene = Scene()
    lidar, camera = Lidar(scene, traj, np.random.default_rng([args.seed, 1])), Camera(scene)
    started = time.time()
    # Messages in the order of their bag time (a sweep is published at its end).
    events = [(t, 0, 'imu', m) for t, m in imu_messages(traj, args.duration, np.random.default_rng([args.seed, 2]))]
    events += [(t, 1, 'gt', m) for t, m in ground_truth_messages(traj, args.duration)]
    # a sweep is published 2 ms after its end, an image 4 ms after its capture
    sweeps = int(math.floor(args.duration * LIDAR_RATE + 1e-9))
    events += [((k + 1) / LIDAR_RATE + 0.002, 2, 'lidar', k / LIDAR_RATE) for k in range(sweeps)]
    images = int(math.floor((args.duration - CAMERA_PHASE) * CAMERA_RATE + 1e-9))
    events += [(CAMERA_PHASE + k / CAMERA_RATE + 0.004, 3, 'camera', CAMERA_PHASE + k / CAMERA_RATE)
               for k in range(images)]
    events.sort(key=lambda e: (e[0], e[1]))
    with rosbag.Bag(args.out, 'w') as bag:
        for t, _, kind, payload in events:
            if kind == 'imu':
                bag.write('/imu/data', payload, stamp(t))
            elif kind == 'gt':
                bag.write('/ground_truth/pose', payload, stamp(t))
            elif kind == 'lidar':
                bag.write('/velodyne_points', lidar.cloud(payload), stamp(t))
            else:
                p, _, R, _, _ = traj.state(np.array([payload]))
                img, info = camera.messages(payload, p[0], R[0])
                bag.write('/camera/image_raw/compressed', img, stamp(t))
                bag.write('/camera/camera_info', info, stamp(t))
    print('wrote %s: %.1f s, %d sweeps, %d images, %d IMU samples, %d poses in %.0f s'
          % (args.out, args.duration, sweeps, images, int(round(args.duration * IMU_RATE)),
             int(round(args.duration * GROUND_TRUTH_RATE)), time.time() - started), file=sys.stderr)


if __name__ == '__main__':
    main()
