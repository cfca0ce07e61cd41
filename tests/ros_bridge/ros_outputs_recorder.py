#!/usr/bin/python3
"""The ROS side of the bridge test: a rospy node that records what livo-ros-bridge sends to ROS,
as RViz would receive it.

  ODOMETRY_TOPIC (nav_msgs/Odometry)      every pose, written to TUM_FILE as it arrives
                                          (stamp x y z qx qy qz qw, the stamp exact to the ns)
  /tf (tf2_msgs/TFMessage)                the transforms WORLD -> BODY, counted
  SCAN_TOPIC (sensor_msgs/PointCloud2)    registered scans: counted, frames and fields checked

Writes READY_FILE once its odometry and scan subscriptions are connected to the bridge, and on
SIGINT a JSON summary to SUMMARY_FILE.

usage: ros_outputs_recorder.py ODOMETRY_TOPIC SCAN_TOPIC WORLD BODY TUM_FILE SUMMARY_FILE READY_FILE
"""
import json
import sys

import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import PointCloud2
from tf2_msgs.msg import TFMessage


def main():
    odometry_topic, scan_topic, world, body, tum_file, summary_file, ready_file = sys.argv[1:8]
    rospy.init_node('livo_test_recorder', disable_signals=False)
    summary = {'odometry': 0, 'odometry_frames': [], 'tf': 0, 'tf_other': 0, 'scans': 0, 'scan_frames': [],
               'scan_fields': [], 'scan_points': 0}
    tum = open(tum_file, 'w')

    def on_odometry(m):
        p, q = m.pose.pose.position, m.pose.pose.orientation
        tum.write('%d.%09d %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n' %
                  (m.header.stamp.secs, m.header.stamp.nsecs, p.x, p.y, p.z, q.x, q.y, q.z, q.w))
        tum.flush()
        summary['odometry'] += 1
        frames = [m.header.frame_id, m.child_frame_id]
        if frames not in summary['odometry_frames']:
            summary['odometry_frames'].append(frames)

    def on_tf(m):
        for t in m.transforms:
            if t.header.frame_id == world and t.child_frame_id == body:
                summary['tf'] += 1
            else:
                summary['tf_other'] += 1

    def on_scan(m):
        summary['scans'] += 1
        summary['scan_points'] += m.width * m.height
        if m.header.frame_id not in summary['scan_frames']:
            summary['scan_frames'].append(m.header.frame_id)
        summary['scan_fields'] = [f.name for f in m.fields]

    odometry = rospy.Subscriber(odometry_topic, Odometry, on_odometry, queue_size=1000, tcp_nodelay=True)
    rospy.Subscriber('/tf', TFMessage, on_tf, queue_size=1000, tcp_nodelay=True)
    scans = rospy.Subscriber(scan_topic, PointCloud2, on_scan, queue_size=100)
    while not rospy.is_shutdown() and (odometry.get_num_connections() == 0 or scans.get_num_connections() == 0):
        rospy.sleep(0.05)
    open(ready_file, 'w').close()
    rospy.spin()
    tum.close()
    with open(summary_file, 'w') as f:
        json.dump(summary, f)


if __name__ == '__main__':
    main()
