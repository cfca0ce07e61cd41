#!/usr/bin/python3
"""Writes a livo-sim LCM log as a ROS 1 driver stack would have recorded it, with Debian's
python3-rosbag and the ROS message classes, so that the ROS bridge test plays a bag that no C++
of this project wrote. The LCM log and the three message types are read here from their published
encodings (LCM's log format and big-endian marshalling), not with the project's code.

  IMU           -> /imu/data           sensor_msgs/Imu (orientation unknown: covariance[0] = -1)
  LIDAR         -> /velodyne_points    sensor_msgs/PointCloud2 as the velodyne_pointcloud driver
                                       writes it: x y z intensity (float32) ring (uint16) time
                                       (float32, seconds after header.stamp = the sweep start),
                                       22 bytes per point; recorded at the sweep's end, when a
                                       driver publishes it
  GROUND_TRUTH  -> /ground_truth/pose  geometry_msgs/PoseStamped
Stamps: the log's microseconds + 1,700,000,000 s (ROS time 0 means "no stamp"). Other channels
are left out.

usage: sim_log_to_bag.py LOG BAG
"""
import struct
import sys

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import Imu, PointCloud2, PointField

BASE_US = 1700000000 * 10**6
LOG_SYNC = 0xEDA1DA01


def stamp(utime):
    us = utime + BASE_US
    return rospy.Time(us // 10**6, (us % 10**6) * 1000)


def log_events(path):
    """(channel, payload) of each event of an LCM log file."""
    with open(path, 'rb') as f:
        data = f.read()
    pos = 0
    while pos + 28 <= len(data):
        sync, _event, _time, channel_len, data_len = struct.unpack_from('>IqqII', data, pos)
        if sync != LOG_SYNC:
            raise ValueError('%s: no LCM event at byte %d' % (path, pos))
        pos += 28
        channel = data[pos:pos + channel_len].decode()
        pos += channel_len
        yield channel, data[pos:pos + data_len]
        pos += data_len


class Reader:
    """Big-endian LCM marshalling of one message, after its 8-byte type fingerprint."""

    def __init__(self, payload):
        self.b, self.pos = payload, 8

    def take(self, fmt):
        v = struct.unpack_from('>' + fmt, self.b, self.pos)
        self.pos += struct.calcsize('>' + fmt)
        return v

    def string(self):
        (n,) = self.take('i')  # length including the terminating NUL
        s = self.b[self.pos:self.pos + n - 1].decode()
        self.pos += n
        return s

    def array(self, dtype, n):
        a = np.frombuffer(self.b, dtype=dtype, count=n, offset=self.pos)
        self.pos += a.nbytes
        return a


def imu_message(payload):
    r = Reader(payload)
    (utime,) = r.take('q')
    w, a = r.take('3d'), r.take('3d')
    m = Imu()
    m.header.stamp = stamp(utime)
    m.header.frame_id = 'imu'
    m.orientation_covariance = [-1.0] + [0.0] * 8
    m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = w
    m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = a
    return m, m.header.stamp


def cloud_message(payload):
    r = Reader(payload)
    (utime,) = r.take('q')
    r.string()  # frame
    r.take('b')  # pattern
    r.take('h')  # num_rings
    (sweep,) = r.take('f')
    (n,) = r.take('i')
    x, y, z, intensity, offset = (r.array('>f4', n) for _ in range(5))
    ring = r.array('>i2', n)
    points = np.zeros(n, dtype=np.dtype({'names': ['x', 'y', 'z', 'intensity', 'ring', 'time'],
                                         'formats': ['<f4', '<f4', '<f4', '<f4', '<u2', '<f4'],
                                         'offsets': [0, 4, 8, 12, 16, 18], 'itemsize': 22}))
    points['x'], points['y'], points['z'], points['intensity'] = x, y, z, intensity
    points['ring'], points['time'] = np.maximum(ring, 0), offset
    m = PointCloud2()
    m.header.stamp = stamp(utime)
    m.header.frame_id = 'velodyne'
    m.height, m.width = 1, n
    m.fields = [PointField(name=name, offset=o, datatype=t, count=1) for name, o, t in
                [('x', 0, PointField.FLOAT32), ('y', 4, PointField.FLOAT32), ('z', 8, PointField.FLOAT32),
                 ('intensity', 12, PointField.FLOAT32), ('ring', 16, PointField.UINT16),
                 ('time', 18, PointField.FLOAT32)]]
    m.is_bigendian = False
    m.point_step, m.row_step = 22, 22 * n
    m.data = points.tobytes()
    m.is_dense = True
    return m, stamp(utime + int(round(sweep * 1e6)))


def pose_message(payload):
    r = Reader(payload)
    (utime,) = r.take('q')
    r.string()
    r.string()
    p, q = r.take('3d'), r.take('4d')
    m = PoseStamped()
    m.header.stamp = stamp(utime)
    m.header.frame_id = 'world'
    m.pose.position.x, m.pose.position.y, m.pose.position.z = p
    m.pose.orientation.w, m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z = q
    return m, m.header.stamp


TOPICS = {'IMU': ('/imu/data', imu_message), 'LIDAR': ('/velodyne_points', cloud_message),
          'GROUND_TRUTH': ('/ground_truth/pose', pose_message)}


def main():
    log, out = sys.argv[1], sys.argv[2]
    counts = {}
    with rosbag.Bag(out, 'w') as bag:
        for channel, payload in log_events(log):
            if channel not in TOPICS:
                continue
            topic, convert = TOPICS[channel]
            msg, t = convert(payload)
            bag.write(topic, msg, t)
            counts[channel] = counts.get(channel, 0) + 1
    print('sim_log_to_bag.py: %s: %s' % (out, ' '.join('%s %d' % kv for kv in sorted(counts.items()))))
    return 0 if counts.get('IMU') and counts.get('LIDAR') else 1


if __name__ == '__main__':
    sys.exit(main())
