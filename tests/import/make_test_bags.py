#!/usr/bin/python3
"""Writes ROS 1 bags with the real ROS library (Debian's python3-rosbag) for the livo-import tests,
one per chunk compression, holding every message type and PointCloud2 layout the importer reads,
plus a bag of malformed messages and a small VLP-16 + IMU + camera bag with CameraInfo topics (the
starter rig of --rig-out). Beside each bag, <bag>.expected.json lists what the import must
produce, computed here from the values written (float32 rounding done with numpy).

usage: make_test_bags.py OUTDIR JPEG_FILE PNG_FILE
"""
import json
import math
import os
import struct
import sys

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import PointStamped, PoseStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, Imu, PointCloud2, PointField
from std_msgs.msg import String

F32, F64, U8, U16, U32 = PointField.FLOAT32, PointField.FLOAT64, PointField.UINT8, PointField.UINT16, PointField.UINT32
FMT = {F32: 'f', F64: 'd', U8: 'B', U16: 'H', U32: 'I'}
BASE_NS = 1600000000 * 10**9 + 123456000  # microsecond-aligned stamps


def stamp(ns):
    return rospy.Time(ns // 10**9, ns % 10**9)


def f32(v):
    return float(np.float32(v))


def cloud_msg(ns, fields, points, point_step, height=1, frame='lidar'):
    """points: list of dicts field->value, packed little-endian at the fields' offsets."""
    msg = PointCloud2()
    msg.header.stamp = stamp(ns)
    msg.header.frame_id = frame
    msg.height = height
    msg.width = len(points) // height
    msg.fields = [PointField(name=n, offset=o, datatype=t, count=1) for (n, o, t) in fields]
    msg.is_bigendian = False
    msg.point_step = point_step
    msg.row_step = point_step * msg.width
    buf = bytearray(point_step * len(points))
    for i, p in enumerate(points):
        for (n, o, t) in fields:
            struct.pack_into('<' + FMT[t], buf, i * point_step + o, p[n])
    msg.data = bytes(buf)
    msg.is_dense = False
    return msg


def xyz(k, j):
    """Deterministic coordinates of point j of cloud k (exactly representable in float32)."""
    return (f32(1.5 + 0.25 * j + k), f32(-2.0 + 0.125 * j), f32(0.5 - 0.0625 * j))


def velodyne(k, ns):
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 12, F32), ('ring', 16, U16), ('time', 18, F32)]
    pts, exp = [], []
    for j in range(12):
        x, y, z = xyz(k, j)
        t = f32(j * 0.0083)
        p = dict(x=x, y=y, z=z, intensity=f32(10.0 + j), ring=j % 16, time=t)
        if j == 5:
            p['x'] = float('nan')  # dropped and counted
        else:
            exp.append([x, y, z, f32(10.0 + j), f32(t), j % 16])
        pts.append(p)
    return cloud_msg(ns, fields, pts, 22), dict(utime=ns // 1000, pattern=0, points=exp)


def velodyne_end_stamped(k, ns):
    """Old Velodyne driver: stamp at the last packet, time <= 0 relative to it."""
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 12, F32), ('ring', 16, U16), ('time', 18, F32)]
    pts, times = [], []
    for j in range(10):
        x, y, z = xyz(k, j)
        t = f32(-0.1 + j * 0.01)
        times.append(t)
        pts.append(dict(x=x, y=y, z=z, intensity=1.0, ring=j, time=t))
    first_ns = math.floor(min(times) * 1e9)
    utime = (ns + first_ns) // 1000
    shift = (ns - utime * 1000) * 1e-9
    exp = [[p['x'], p['y'], p['z'], 1.0, f32(t + shift), p['ring']] for p, t in zip(pts, times)]
    return cloud_msg(ns, fields, pts, 22), dict(utime=utime, pattern=0, points=exp)


def ouster(k, ns, rings=4, cols=6):
    """ouster_ros layout, organised (height = rings), with no-return points at (0, 0, 0)."""
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 16, F32), ('t', 20, U32),
              ('reflectivity', 24, U16), ('ring', 26, U8), ('ambient', 28, U16), ('range', 32, U32)]
    pts, exp = [], []
    for r in range(rings):
        for c in range(cols):
            j = r * cols + c
            x, y, z = xyz(k, j)
            t = c * 15625000 + 1000  # ns after the stamp, one column every 15.6 ms
            if (r + c) % 7 == 3:
                pts.append(dict(x=0.0, y=0.0, z=0.0, intensity=0.0, t=t, reflectivity=0, ring=r, ambient=0, range=0))
                continue
            pts.append(dict(x=x, y=y, z=z, intensity=f32(100 + j), t=t, reflectivity=7, ring=r, ambient=3, range=1000))
            exp.append([x, y, z, f32(100 + j), f32(t * 1e-9), r])
    return cloud_msg(ns, fields, pts, 48, height=rings), dict(utime=ns // 1000, pattern=0, points=exp)


def hesai(k, ns):
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 12, F32), ('timestamp', 16, F64), ('ring', 24, U16)]
    pts, abs_t = [], []
    for j in range(9):
        x, y, z = xyz(k, j)
        a = ns * 1e-9 + 0.000004 + j * 0.0111
        abs_t.append(a)
        pts.append(dict(x=x, y=y, z=z, intensity=f32(j), timestamp=a, ring=31 - j))
    first_ns = math.floor(min(abs_t) * 1e9)
    utime = min(ns, first_ns) // 1000
    exp = [[p['x'], p['y'], p['z'], p['intensity'], f32(a - utime * 1e-6), p['ring']] for p, a in zip(pts, abs_t)]
    return cloud_msg(ns, fields, pts, 32), dict(utime=utime, pattern=0, points=exp)


def livox(k, ns):
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 12, F32), ('tag', 16, U8), ('line', 17, U8),
              ('offset_time', 18, U32)]
    pts, exp = [], []
    for j in range(11):
        x, y, z = xyz(k, j)
        ot = j * 9090909
        pts.append(dict(x=x, y=y, z=z, intensity=f32(j * 2), tag=16, line=j % 6, offset_time=ot))
        exp.append([x, y, z, f32(j * 2), f32(ot * 1e-9), j % 6])
    return cloud_msg(ns, fields, pts, 22), dict(utime=ns // 1000, pattern=1, points=exp)


def imu_msg(i):
    m = Imu()
    ns = BASE_NS + i * 5000000
    m.header.stamp = stamp(ns)
    m.orientation.w = 1.0
    m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = 0.01 * i, -0.02, 0.5 + i * 1e-3
    m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = 0.1, 0.2 * i, 9.81
    return m, dict(utime=ns // 1000, gyro=[0.01 * i, -0.02, 0.5 + i * 1e-3], accel=[0.1, 0.2 * i, 9.81])


LAYOUTS = {'/velodyne_points': velodyne, '/velodyne_end': velodyne_end_stamped, '/ouster/points': ouster,
           '/hesai/pandar': hesai, '/livox/lidar': livox}


def write_layout_bag(path, compression, jpeg, png):
    expected = dict(imu=[], clouds={t: [] for t in LAYOUTS}, image=[], compressed=[], odom=[], pose=[])
    with rosbag.Bag(path, 'w', compression=compression, chunk_threshold=2048) as bag:
        for i in range(40):
            m, e = imu_msg(i)
            bag.write('/imu', m, m.header.stamp)
            expected['imu'].append(e)
        for k in range(3):
            ns = BASE_NS + k * 100000000
            for topic, make in LAYOUTS.items():
                msg, e = make(k, ns)
                bag.write(topic, msg, msg.header.stamp)
                expected['clouds'][topic].append(e)
            img = Image()
            img.header.stamp = stamp(ns + 1000)
            img.height, img.width, img.encoding, img.step = 3, 4, 'rgb8', 16  # 4 bytes of row padding
            img.data = bytes((k * 50 + b) % 256 for b in range(48))
            bag.write('/camera/image_raw', img, img.header.stamp)
            expected['image'].append(dict(utime=(ns + 1000) // 1000, width=4, height=3, stride=16, encoding=1,
                                          data=list(img.data)))
            ci = CompressedImage()
            ci.header.stamp = stamp(ns + 2000)
            ci.format = 'jpeg' if k % 2 == 0 else 'png'
            ci.data = jpeg if k % 2 == 0 else png
            bag.write('/camera/compressed', ci, ci.header.stamp)
            expected['compressed'].append(dict(utime=(ns + 2000) // 1000, encoding=10 if k % 2 == 0 else 11,
                                               size=len(ci.data)))
            od = Odometry()
            od.header.stamp = stamp(ns + 3000)
            od.child_frame_id = 'body'
            od.pose.pose.position.x, od.pose.pose.position.y, od.pose.pose.position.z = 1.0 + k, 2.0, 3.0
            od.pose.pose.orientation.x, od.pose.pose.orientation.w = math.sin(0.1 * k), math.cos(0.1 * k)
            bag.write('/gt/odom', od, od.header.stamp)
            expected['odom'].append(dict(utime=(ns + 3000) // 1000, position=[1.0 + k, 2.0, 3.0],
                                         wxyz=[math.cos(0.1 * k), math.sin(0.1 * k), 0.0, 0.0]))
            ps = PoseStamped()
            ps.header.stamp = stamp(ns + 4000)
            ps.pose.position.x, ps.pose.position.y, ps.pose.position.z = -1.0, k * 0.5, 0.25
            ps.pose.orientation.z, ps.pose.orientation.w = math.sin(0.2), math.cos(0.2)
            bag.write('/gt/pose', ps, ps.header.stamp)
            expected['pose'].append(dict(utime=(ns + 4000) // 1000, position=[-1.0, k * 0.5, 0.25],
                                         wxyz=[math.cos(0.2), 0.0, 0.0, math.sin(0.2)]))
        bag.write('/chatter', String(data='not a sensor'), stamp(BASE_NS))
    with open(path + '.expected.json', 'w') as f:
        json.dump(expected, f)


def write_ntu_viral_bag(path):
    """NTU VIRAL's topics and conventions: OS1-16 clouds stamped at the sweep end with t from
    the sweep start, VN100 IMU, mono8 cameras, the Leica prism as PointStamped."""
    expected = dict(imu=[], clouds=[], left=[], right=[], prism=[])
    with rosbag.Bag(path, 'w', compression='lz4', chunk_threshold=4096) as bag:
        for i in range(20):
            m, e = imu_msg(i)
            bag.write('/imu/imu', m, m.header.stamp)
            expected['imu'].append(e)
        for k in range(3):
            end_ns = BASE_NS + (k + 1) * 100000000
            msg, e = ouster(k, end_ns, rings=16, cols=4)
            bag.write('/os1_cloud_node1/points', msg, msg.header.stamp)
            e['utime'] = (end_ns - 100000000) // 1000
            expected['clouds'].append(e)
            msg2, _ = ouster(k, end_ns, rings=16, cols=4)
            bag.write('/os1_cloud_node2/points', msg2, msg2.header.stamp)
            for topic, key in (('/left/image_raw', 'left'), ('/right/image_raw', 'right')):
                img = Image()
                img.header.stamp = stamp(end_ns + 5000)
                img.height, img.width, img.encoding, img.step = 2, 3, 'mono8', 3
                img.data = bytes([k, 1, 2, 3, 4, 5 + len(key)])
                bag.write(topic, img, img.header.stamp)
                expected[key].append(dict(utime=(end_ns + 5000) // 1000, data=list(img.data)))
            p = PointStamped()
            p.header.stamp = stamp(end_ns + 7000)
            p.point.x, p.point.y, p.point.z = 0.5 * k, -0.25, 1.125
            bag.write('/leica/pose/relative', p, p.header.stamp)
            expected['prism'].append(dict(utime=(end_ns + 7000) // 1000, position=[0.5 * k, -0.25, 1.125]))
    with open(path + '.expected.json', 'w') as f:
        json.dump(expected, f)


def write_bad_bag(path):
    """Messages the importer must refuse with a reason naming the field, next to good ones."""
    with rosbag.Bag(path, 'w', compression='none') as bag:
        good, _ = velodyne(0, BASE_NS)
        bag.write('/points', good, good.header.stamp)
        no_z = cloud_msg(BASE_NS + 10**8, [('x', 0, F32), ('y', 4, F32), ('time', 8, F32)],
                         [dict(x=1.0, y=2.0, time=0.0)], 12)
        bag.write('/points', no_z, no_z.header.stamp)
        ns_as_seconds = cloud_msg(BASE_NS + 2 * 10**8, [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('time', 12, F32)],
                                  [dict(x=1.0, y=2.0, z=3.0, time=0.0), dict(x=1.0, y=2.0, z=3.0, time=5e7)], 16)
        bag.write('/points', ns_as_seconds, ns_as_seconds.header.stamp)
        short = cloud_msg(BASE_NS + 3 * 10**8, [('x', 0, F32), ('y', 4, F32), ('z', 8, F32)],
                          [dict(x=1.0, y=2.0, z=3.0)] * 4, 12)
        short.data = short.data[:20]  # fewer bytes than width * point_step
        bag.write('/points', short, short.header.stamp)
        img = Image()
        img.header.stamp = stamp(BASE_NS)
        img.height, img.width, img.encoding, img.step = 2, 2, 'yuv422', 4
        img.data = bytes(8)
        bag.write('/camera', img, img.header.stamp)
        for i in range(5):
            m, _ = imu_msg(i)
            bag.write('/imu', m, m.header.stamp)


def depth_images(k, ns):
    """An RGB-D camera's frame k: rgb8 colour, aligned depth as 16UC1 (mm, little-endian) and the
    same as 32FC1 (m, big-endian, one NaN), 3 x 2 pixels, with padded rows."""
    colour = Image()
    colour.header.stamp = stamp(ns)
    colour.height, colour.width, colour.encoding, colour.step = 2, 3, 'rgb8', 9
    colour.data = bytes(range(k, k + 18))
    mm = [0, 500 + k, 1000, 2500, 65535, 7]
    d16 = Image()
    d16.header.stamp = stamp(ns)
    d16.height, d16.width, d16.encoding, d16.is_bigendian, d16.step = 2, 3, '16UC1', 0, 8
    d16.data = b''.join(struct.pack('<3H', *mm[3 * j:3 * j + 3]) + b'\x00\x00' for j in range(2))
    metres = [0.0, 0.5 + k * 1e-3, 1.0, float('nan'), 65.535, 0.007]
    d32 = Image()
    d32.header.stamp = stamp(ns)
    d32.height, d32.width, d32.encoding, d32.is_bigendian, d32.step = 2, 3, '32FC1', 1, 12
    d32.data = struct.pack('>6f', *metres)
    return colour, d16, d32, dict(utime=ns // 1000, millimetres=mm, metres=[None if math.isnan(v) else v for v in metres])


def write_rgbd_bags(one_path, two_path):
    """A RealSense-like RGB-D camera: colour and aligned depth (16UC1) in one bag; colour and depth
    as 16UC1 and as 32FC1 in the other (two depth topics: none is chosen unless named)."""
    expected = dict(depth=[])
    with rosbag.Bag(one_path, 'w', compression='none') as one, rosbag.Bag(two_path, 'w', compression='lz4') as two:
        for i in range(10):
            m, _ = imu_msg(i)
            one.write('/imu', m, m.header.stamp)
            two.write('/imu', m, m.header.stamp)
        for k in range(3):
            ns = BASE_NS + k * 50000000 + 3000
            colour, d16, d32, e = depth_images(k, ns)
            for bag in (one, two):
                bag.write('/camera/color/image_raw', colour, colour.header.stamp)
                bag.write('/camera/aligned_depth_to_color/image_raw', d16, d16.header.stamp)
            two.write('/camera/depth/image_float', d32, d32.header.stamp)
            expected['depth'].append(e)
    for path in (one_path, two_path):
        with open(path + '.expected.json', 'w') as f:
            json.dump(expected, f)


def write_camera_info_bag(path):
    """1.5 s of a VLP-16 (16 rings, Velodyne time field) at 10 Hz, an IMU at 200 Hz at rest (|a| =
    9.8), rgb8 images of 8 x 6 at 20 Hz with a calibrated plumb_bob CameraInfo in the camera's
    namespace, and a second CameraInfo elsewhere (not the camera's: must not be chosen)."""
    expected = dict(camera_info=dict(width=8, height=6, fx=5.5, fy=5.25, cx=3.5, cy=2.5,
                                     D=[-0.1, 0.01, 0.001, -0.002, 0.0005]),
                    imu_hz=200, lidar_hz=10, camera_hz=20, rings=16)
    fields = [('x', 0, F32), ('y', 4, F32), ('z', 8, F32), ('intensity', 12, F32), ('ring', 16, U16), ('time', 18, F32)]
    with rosbag.Bag(path, 'w', compression='none') as bag:
        for i in range(300):
            m = Imu()
            ns = BASE_NS + i * 5000000
            m.header.stamp = stamp(ns)
            m.linear_acceleration.z = 9.8
            bag.write('/imu/data', m, m.header.stamp)
        for k in range(15):
            ns = BASE_NS + k * 100000000
            pts = [dict(x=f32(2.0 + 0.1 * j), y=f32(0.5 * math.sin(j)), z=f32(-0.2 + 0.02 * j), intensity=1.0,
                        ring=j % 16, time=f32(j * 0.003)) for j in range(32)]
            msg = cloud_msg(ns, fields, pts, 22, frame='velodyne')
            bag.write('/velodyne_points', msg, msg.header.stamp)
        for k in range(30):
            ns = BASE_NS + k * 50000000 + 7000
            img = Image()
            img.header.stamp = stamp(ns)
            img.height, img.width, img.encoding, img.step = 6, 8, 'rgb8', 24
            img.data = bytes((k + b) % 256 for b in range(144))
            bag.write('/camera/image_raw', img, img.header.stamp)
            ci = expected['camera_info']
            info = CameraInfo()
            info.header.stamp = img.header.stamp
            info.width, info.height = ci['width'], ci['height']
            info.distortion_model = 'plumb_bob'
            info.D = ci['D']
            info.K = [ci['fx'], 0.0, ci['cx'], 0.0, ci['fy'], ci['cy'], 0.0, 0.0, 1.0]
            info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
            info.P = [ci['fx'], 0.0, ci['cx'], 0.0, 0.0, ci['fy'], ci['cy'], 0.0, 0.0, 0.0, 1.0, 0.0]
            bag.write('/camera/camera_info', info, info.header.stamp)
            other = CameraInfo()
            other.header.stamp = img.header.stamp
            other.width, other.height = 100, 50
            other.distortion_model = 'equidistant'
            other.D = [0.1, 0.2, 0.3, 0.4]
            other.K = [40.0, 0.0, 50.0, 0.0, 40.0, 25.0, 0.0, 0.0, 1.0]
            bag.write('/thermal/camera_info', other, other.header.stamp)
    with open(path + '.expected.json', 'w') as f:
        json.dump(expected, f)


def main():
    out, jpeg_path, png_path = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(out, exist_ok=True)
    jpeg = open(jpeg_path, 'rb').read()
    png = open(png_path, 'rb').read()
    for compression in ('none', 'bz2', 'lz4'):
        write_layout_bag(os.path.join(out, 'layouts_%s.bag' % compression), compression, jpeg, png)
    write_ntu_viral_bag(os.path.join(out, 'ntu_viral.bag'))
    write_bad_bag(os.path.join(out, 'bad.bag'))
    write_rgbd_bags(os.path.join(out, 'rgbd.bag'), os.path.join(out, 'rgbd_two_depths.bag'))
    write_camera_info_bag(os.path.join(out, 'camera_info.bag'))
    print('wrote test bags to', out)


if __name__ == '__main__':
    main()
