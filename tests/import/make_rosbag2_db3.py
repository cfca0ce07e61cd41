#!/usr/bin/env python3
"""Writes rosbag2 SQLite bags (.db3) of the messages make_rosbag2_fixtures.js serialised (its
rows.json: topic, type, log time, CDR bytes from @foxglove/rosmsg2-serialization), with Python's
sqlite3 and rosbag2's schema (tables topics and messages, as rosbag2_storage_default_plugins
creates them).

    make_rosbag2_db3.py FIXTURE_DIR

FIXTURE_DIR gets bag_db3/ (metadata.yaml + bag_db3_0.db3), single.db3 (the same, alone) and
bad_topic.db3 (a message row whose topic_id the topics table lacks, after two good rows).
"""
import base64
import json
import os
import sqlite3
import sys

SCHEMA = """
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                    serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL,
                    type_description_hash TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,
                      data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
"""


def write_db3(path, rows, bad_topic_after=None):
    if os.path.exists(path):
        os.remove(path)
    db = sqlite3.connect(path)
    db.executescript(SCHEMA)
    db.execute("INSERT INTO schema VALUES (4, 'humble')")
    topic_ids = {}
    for r in rows:
        if r["topic"] not in topic_ids:
            topic_ids[r["topic"]] = len(topic_ids) + 1
            db.execute("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '', '')",
                       (topic_ids[r["topic"]], r["topic"], r["type"]))
    for i, r in enumerate(rows):
        topic_id = topic_ids[r["topic"]]
        if bad_topic_after is not None and i == bad_topic_after:
            topic_id = 99
        db.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                   (topic_id, int(r["timestamp"]), base64.b64decode(r["data"])))
    db.commit()
    db.close()


def metadata_yaml(rows, file):
    counts = {}
    for r in rows:
        counts.setdefault(r["topic"], [r["type"], 0])[1] += 1
    stamps = [int(r["timestamp"]) for r in rows]
    y = ["rosbag2_bagfile_information:", "  version: 5", "  storage_identifier: sqlite3",
         "  duration:", f"    nanoseconds: {max(stamps) - min(stamps)}",
         "  starting_time:", f"    nanoseconds_since_epoch: {min(stamps)}",
         f"  message_count: {len(rows)}", "  topics_with_message_count:"]
    for topic, (type_, n) in counts.items():
        y += ["    - topic_metadata:", f"        name: {topic}", f"        type: {type_}",
              "        serialization_format: cdr", '        offered_qos_profiles: ""',
              f"      message_count: {n}"]
    y += ['  compression_format: ""', '  compression_mode: ""', "  relative_file_paths:", f"    - {file}"]
    return "\n".join(y) + "\n"


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "rows.json")) as f:
        rows = json.load(f)
    bag = os.path.join(out, "bag_db3")
    os.makedirs(bag, exist_ok=True)
    write_db3(os.path.join(bag, "bag_db3_0.db3"), rows)
    with open(os.path.join(bag, "metadata.yaml"), "w") as f:
        f.write(metadata_yaml(rows, "bag_db3_0.db3"))
    write_db3(os.path.join(out, "single.db3"), rows)
    write_db3(os.path.join(out, "bad_topic.db3"), rows, bad_topic_after=2)


if __name__ == "__main__":
    main()
