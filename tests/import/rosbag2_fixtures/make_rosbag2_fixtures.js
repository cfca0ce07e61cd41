// Writes the ROS 2 bags livo-import's rosbag2 tests read, with other implementations than the
// reader under test: CDR from @foxglove/rosmsg2-serialization (ROS 2 Humble's message definitions
// from @foxglove/rosmsg-msgs-common; the big-endian IMU through @foxglove/cdr's CdrWriter), MCAP
// from @mcap/core's McapWriter (chunks: none, zstd by @foxglove/wasm-zstd, lz4 by lz4js).
//
//   node make_rosbag2_fixtures.js OUT_DIR JPEG
//
// OUT_DIR gets: unchunked.mcap (with a summary), unchunked_nosummary.mcap (no summary, no index),
// chunked_{none,zstd,lz4}.mcap, bag_mcap/ (metadata.yaml + a zstd-chunked file), bag_split/ (two
// files), bag_zstd_file/ and bag_zstd_message/ (rosbag2's zstd compression, per file and per
// message), ros1_encoded.mcap (the IMU in ROS 1 serialisation), truncated.mcap (a chunked file cut inside its data section), rows.json (the same messages for make_rosbag2_db3.py)
// and expected.json (every value written, for the tests to compare field by field).
"use strict";

const fs = require("fs");
const path = require("path");
const { McapWriter, TempBuffer } = require("@mcap/core");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const { CdrWriter, EncapsulationKind } = require("@foxglove/cdr");
const { ros1, ros2humble } = require("@foxglove/rosmsg-msgs-common");
const { MessageWriter: Ros1MessageWriter } = require("@foxglove/rosmsg-serialization");
const zstd = require("@foxglove/wasm-zstd");
const lz4 = require("lz4js");

const [outDir, jpegPath] = process.argv.slice(2);
if (!outDir || !jpegPath) {
  console.error("usage: node make_rosbag2_fixtures.js OUT_DIR JPEG");
  process.exit(2);
}

/// The definition of `type` and every type it uses, as MessageWriter wants them (root first).
function definitionsOf(type) {
  const out = [];
  const seen = new Set();
  const visit = (t) => {
    if (seen.has(t)) return;
    seen.add(t);
    const def = ros2humble[t];
    if (!def) throw new Error(`no ROS 2 definition of ${t}`);
    out.push(def);
    for (const f of def.definitions) if (f.isComplex) visit(f.type);
  };
  visit(type);
  return out;
}

/// ROS 2 type name: "sensor_msgs/Imu" -> "sensor_msgs/msg/Imu".
const ros2Name = (t) => t.replace("/", "/msg/");

/// A .msg-like text of the definitions (the Schema record's data).
function schemaText(type) {
  return definitionsOf(type)
    .map((d, i) => {
      const body = d.definitions
        .filter((f) => !f.isConstant)
        .map((f) => `${f.type}${f.isArray ? `[${f.arrayLength ?? ""}]` : ""} ${f.name}`)
        .join("\n");
      return (i ? `================================================================================\nMSG: ${d.name}\n` : "") + body;
    })
    .join("\n");
}

const writers = new Map();
function cdr(type, msg) {
  if (!writers.has(type)) writers.set(type, new MessageWriter(definitionsOf(type)));
  return writers.get(type).writeMessage(msg);
}

const T0 = 1700000000;
const stamp = (sec, nanosec) => ({ sec, nanosec });
const header = (sec, nanosec, frame_id) => ({ stamp: stamp(sec, nanosec), frame_id });

// ---- the messages -------------------------------------------------------------------------
const messages = []; // {topic, type, logTime (ns, BigInt), data (Uint8Array)}
const expected = { imu: [], imu_be: [], points: [], image: [], compressed: [], camera_info: null, odom: [], pose: [], tf: [],
                   tf_odom: [], tf_base_link: [] };
const add = (topic, type, sec, nanosec, data) =>
  messages.push({ topic, type, logTime: BigInt(sec) * 1000000000n + BigInt(nanosec) + 1000n, data });

const ros1Imu = [];
for (let k = 0; k < 6; ++k) {
  const sec = T0, nanosec = 100000000 + k * 5000000;
  const m = {
    header: header(sec, nanosec, "imu_link"),
    orientation: { x: 0.01 * k, y: -0.02, z: 0.03, w: 0.999 },
    orientation_covariance: Array.from({ length: 9 }, (_, i) => 0.001 * (i + 1)),
    angular_velocity: { x: 0.1 + 0.01 * k, y: -0.2 - 0.003 * k, z: 0.3 + 0.007 * k },
    angular_velocity_covariance: Array.from({ length: 9 }, (_, i) => 0.002 * (i + 1)),
    linear_acceleration: { x: 0.5 - 0.01 * k, y: -0.25, z: 9.79 + 0.001 * k },
    linear_acceleration_covariance: Array.from({ length: 9 }, (_, i) => 0.003 * (i + 1)),
  };
  let data = cdr("sensor_msgs/Imu", m);
  if (k === 3) data = data.slice(0, 150); // cut inside angular_velocity: undecodable
  add("/imu", "sensor_msgs/Imu", sec, nanosec, data);
  if (k !== 3) {
    // The same sample in ROS 1 serialisation (an MCAP file converted from a ROS 1 bag).
    ros1Imu.push({ logTime: BigInt(sec) * 1000000000n + BigInt(nanosec), data: new Ros1MessageWriter(
      [ros1["sensor_msgs/Imu"], ros1["std_msgs/Header"], ros1["geometry_msgs/Quaternion"], ros1["geometry_msgs/Vector3"]])
      .writeMessage({ ...m, header: { seq: k, stamp: { sec, nsec: nanosec }, frame_id: "imu_link" } }) });
  }
  if (k !== 3)
    expected.imu.push({ sec, nanosec, w: [m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z],
                        a: [m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z] });
  else expected.imu_truncated = { size: data.length };
}

// A big-endian IMU, field by field through CdrWriter (MessageWriter writes little-endian only).
for (let k = 0; k < 3; ++k) {
  const sec = T0, nanosec = 102000000 + k * 5000000;
  const w = new CdrWriter({ kind: EncapsulationKind.CDR_BE });
  const av = [0.5 + k, -1.25, 2.0e-3 * (k + 1)], la = [-9.81, 0.125 * k, 3.5];
  w.int32(sec); w.uint32(nanosec); w.string("imu_be");
  for (const q of [0, 0, 0, 1]) w.float64(q);
  for (let i = 0; i < 9; ++i) w.float64(0.1 * i);
  for (const v of av) w.float64(v);
  for (let i = 0; i < 9; ++i) w.float64(0.2 * i);
  for (const v of la) w.float64(v);
  for (let i = 0; i < 9; ++i) w.float64(0.3 * i);
  add("/imu_be", "sensor_msgs/Imu", sec, nanosec, w.data);
  expected.imu_be.push({ sec, nanosec, w: av, a: la });
}

// PointCloud2, Velodyne layout with padding: x y z intensity (float32), ring (uint16) at 16,
// time (float32, s after the stamp) at 20, point_step 28 (4 bytes of padding at the end).
for (let c = 0; c < 2; ++c) {
  const sec = T0, nanosec = 150000000 + c * 100000000;
  const n = 8, step = 28;
  const buf = new DataView(new ArrayBuffer(n * step));
  const pts = [];
  for (let j = 0; j < n; ++j) {
    const p = [Math.fround(1 + j + c), Math.fround(-2 + 0.5 * j), Math.fround(0.25 * j - 1), Math.fround(10 * j + c),
               j % 4, Math.fround(0.01 * j)];
    buf.setFloat32(j * step + 0, p[0], true);
    buf.setFloat32(j * step + 4, p[1], true);
    buf.setFloat32(j * step + 8, p[2], true);
    buf.setFloat32(j * step + 12, p[3], true);
    buf.setUint16(j * step + 16, p[4], true);
    buf.setFloat32(j * step + 20, p[5], true);
    pts.push(p);
  }
  const f = (name, offset, datatype) => ({ name, offset, datatype, count: 1 });
  const m = {
    header: header(sec, nanosec, "velodyne"),
    height: 1, width: n,
    fields: [f("x", 0, 7), f("y", 4, 7), f("z", 8, 7), f("intensity", 12, 7), f("ring", 16, 4), f("time", 20, 7)],
    is_bigendian: false, point_step: step, row_step: n * step,
    data: new Uint8Array(buf.buffer), is_dense: true,
  };
  add("/points", "sensor_msgs/PointCloud2", sec, nanosec, cdr("sensor_msgs/PointCloud2", m));
  expected.points.push({ sec, nanosec, points: pts });
}

// Image mono8 4x3 with a row stride of 5, and CameraInfo.
for (let k = 0; k < 2; ++k) {
  const sec = T0, nanosec = 120000000 + k * 50000000;
  const data = Array.from({ length: 15 }, (_, i) => (i * 17 + k * 3) % 256);
  add("/camera/image_raw", "sensor_msgs/Image", sec, nanosec,
      cdr("sensor_msgs/Image", { header: header(sec, nanosec, "cam"), height: 3, width: 4, encoding: "mono8",
                                 is_bigendian: 0, step: 5, data: new Uint8Array(data) }));
  expected.image.push({ sec, nanosec, width: 4, height: 3, step: 5, data });
}
{
  const sec = T0, nanosec = 110000000;
  const ci = {
    header: header(sec, nanosec, "cam"), height: 3, width: 4, distortion_model: "plumb_bob",
    d: [-0.28, 0.07, 0.0002, 0.00002, -0.003],
    k: [458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1],
    r: [1, 0, 0, 0, 1, 0, 0, 0, 1],
    p: [458.654, 0, 367.215, 0, 0, 457.296, 248.375, 0, 0, 0, 1, 0],
    binning_x: 0, binning_y: 0,
    roi: { x_offset: 0, y_offset: 0, height: 0, width: 0, do_rectify: false },
  };
  add("/camera/camera_info", "sensor_msgs/CameraInfo", sec, nanosec, cdr("sensor_msgs/CameraInfo", ci));
  expected.camera_info = { width: 4, height: 3, distortion_model: "plumb_bob", D: ci.d, K: ci.k };
}

// CompressedImage: a JPEG file.
{
  const jpeg = fs.readFileSync(jpegPath);
  const sec = T0, nanosec = 130000000;
  add("/cam1/compressed", "sensor_msgs/CompressedImage", sec, nanosec,
      cdr("sensor_msgs/CompressedImage", { header: header(sec, nanosec, "cam1"), format: "jpeg", data: new Uint8Array(jpeg) }));
  expected.compressed.push({ sec, nanosec, size: jpeg.length });
}

// Ground truth: Odometry (with covariances), PoseStamped, TransformStamped, TFMessage.
for (let k = 0; k < 3; ++k) {
  const sec = T0 + 1, nanosec = k * 200000000;
  const p = { x: 1.5 + k, y: -0.5 * k, z: 0.25 }, q = { x: 0.1, y: 0.2 - 0.05 * k, z: -0.3, w: 0.927 };
  add("/odom", "nav_msgs/Odometry", sec, nanosec, cdr("nav_msgs/Odometry", {
    header: header(sec, nanosec, "map"), child_frame_id: "base_link",
    pose: { pose: { position: p, orientation: q }, covariance: Array.from({ length: 36 }, (_, i) => i * 0.5) },
    twist: { twist: { linear: { x: 1, y: 2, z: 3 }, angular: { x: 4, y: 5, z: 6 } },
             covariance: Array.from({ length: 36 }, (_, i) => -i) },
  }));
  expected.odom.push({ sec, nanosec, p: [p.x, p.y, p.z], q: [q.w, q.x, q.y, q.z] });
  const p2 = { x: -p.x, y: p.y + 3, z: 1 + k };
  add("/pose", "geometry_msgs/PoseStamped", sec, nanosec + 1000, cdr("geometry_msgs/PoseStamped", {
    header: header(sec, nanosec + 1000, "map"), pose: { position: p2, orientation: q } }));
  expected.pose.push({ sec, nanosec: nanosec + 1000, p: [p2.x, p2.y, p2.z], q: [q.w, q.x, q.y, q.z] });
  const t = { x: 7 + k, y: 8, z: -9 };
  add("/tf_gt", "geometry_msgs/TransformStamped", sec, nanosec + 2000, cdr("geometry_msgs/TransformStamped", {
    header: header(sec, nanosec + 2000, "map"), child_frame_id: "body",
    transform: { translation: t, rotation: q } }));
  expected.tf.push({ sec, nanosec: nanosec + 2000, p: [t.x, t.y, t.z], q: [q.w, q.x, q.y, q.z] });
  // tf2_msgs/TFMessage on /tf: map -> odom (fixed) and odom -> base_link (moving) in each message.
  const b = { x: 0.5 * k, y: 1 - 0.25 * k, z: 0.125 }, identity = { x: 0, y: 0, z: 0, w: 1 };
  add("/tf", "tf2_msgs/TFMessage", sec, nanosec + 3000, cdr("tf2_msgs/TFMessage", { transforms: [
    { header: header(sec, nanosec + 3000, "map"), child_frame_id: "odom",
      transform: { translation: { x: 0, y: 0, z: 0 }, rotation: identity } },
    { header: header(sec, nanosec + 3000, "odom"), child_frame_id: "base_link",
      transform: { translation: b, rotation: q } }] }));
  expected.tf_odom.push({ sec, nanosec: nanosec + 3000, p: [0, 0, 0], q: [1, 0, 0, 0] });
  expected.tf_base_link.push({ sec, nanosec: nanosec + 3000, p: [b.x, b.y, b.z], q: [q.w, q.x, q.y, q.z] });
}

// A topic nobody maps.
add("/chatter", "std_msgs/String", T0, 140000000, cdr("std_msgs/String", { data: "hello" }));

// ---- the files ----------------------------------------------------------------------------
async function writeMcap(file, options, part = messages, compressMessage = (d) => d) {
  const buffer = new TempBuffer();
  const writer = new McapWriter({ writable: buffer, ...options });
  await writer.start({ profile: "ros2", library: "livo-lcm test fixture (@mcap/core)" });
  const channels = new Map();
  for (const m of part) {
    if (!channels.has(m.topic)) {
      const schemaId = await writer.registerSchema({
        name: ros2Name(m.type), encoding: "ros2msg", data: new TextEncoder().encode(schemaText(m.type)) });
      channels.set(m.topic, await writer.registerChannel({
        topic: m.topic, messageEncoding: "cdr", schemaId, metadata: new Map([["offered_qos_profiles", ""]]) }));
    }
  }
  let seq = 0;
  for (const m of part)
    await writer.addMessage({ channelId: channels.get(m.topic), sequence: seq++, logTime: m.logTime,
                              publishTime: m.logTime, data: compressMessage(m.data) });
  await writer.end();
  const bytes = buffer.get();
  fs.writeFileSync(file, bytes);
  return bytes;
}

async function main() {
  await zstd.isLoaded;
  fs.mkdirSync(outDir, { recursive: true });
  const small = 1024; // several chunks per file
  await writeMcap(path.join(outDir, "unchunked.mcap"), { useChunks: false });
  await writeMcap(path.join(outDir, "unchunked_nosummary.mcap"), {
    useChunks: false, useStatistics: false, useSummaryOffsets: false, repeatSchemas: false, repeatChannels: false,
    useAttachmentIndex: false, useMetadataIndex: false, useMessageIndex: false, useChunkIndex: false });
  await writeMcap(path.join(outDir, "chunked_none.mcap"), { chunkSize: small });
  await writeMcap(path.join(outDir, "chunked_zstd.mcap"), {
    chunkSize: small, compressChunk: (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) }) });
  const lz4Bytes = await writeMcap(path.join(outDir, "chunked_lz4.mcap"), {
    chunkSize: small, compressChunk: (d) => ({ compression: "lz4", compressedData: new Uint8Array(lz4.compress(d)) }) });
  // Cut inside the data section (which ends past half of the file; the summary follows it): the
  // messages of the chunks before the cut stay readable.
  fs.writeFileSync(path.join(outDir, "truncated.mcap"), lz4Bytes.slice(0, Math.floor(lz4Bytes.length * 0.4)));

  const bagDir = path.join(outDir, "bag_mcap");
  fs.mkdirSync(bagDir, { recursive: true });
  await writeMcap(path.join(bagDir, "bag_mcap_0.mcap"), {
    chunkSize: small, compressChunk: (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) }) });
  fs.writeFileSync(path.join(bagDir, "metadata.yaml"), metadataYaml("mcap", ["bag_mcap_0.mcap"]));

  // A bag split in two files (rosbag2's --max-bag-size): the first half of the messages, then the rest.
  const splitDir = path.join(outDir, "bag_split");
  fs.mkdirSync(splitDir, { recursive: true });
  const half = Math.floor(messages.length / 2);
  await writeMcap(path.join(splitDir, "bag_split_0.mcap"), { chunkSize: small }, messages.slice(0, half));
  await writeMcap(path.join(splitDir, "bag_split_1.mcap"), { useChunks: false }, messages.slice(half));
  fs.writeFileSync(path.join(splitDir, "metadata.yaml"),
                   metadataYaml("mcap", ["bag_split_0.mcap", "bag_split_1.mcap"]));

  // rosbag2's own compression (zstd): each file (mode FILE), each message's payload (mode MESSAGE).
  const fileDir = path.join(outDir, "bag_zstd_file");
  fs.mkdirSync(fileDir, { recursive: true });
  const plainBytes = await writeMcap(path.join(fileDir, "plain.tmp"), { chunkSize: small });
  fs.unlinkSync(path.join(fileDir, "plain.tmp"));
  fs.writeFileSync(path.join(fileDir, "bag_zstd_file_0.mcap.zstd"), zstd.compress(plainBytes, 3));
  fs.writeFileSync(path.join(fileDir, "metadata.yaml"), metadataYaml("mcap", ["bag_zstd_file_0.mcap.zstd"], "FILE"));
  const messageDir = path.join(outDir, "bag_zstd_message");
  fs.mkdirSync(messageDir, { recursive: true });
  await writeMcap(path.join(messageDir, "bag_zstd_message_0.mcap"), { chunkSize: small }, messages,
                  (d) => zstd.compress(d, 3));
  fs.writeFileSync(path.join(messageDir, "metadata.yaml"),
                   metadataYaml("mcap", ["bag_zstd_message_0.mcap"], "MESSAGE"));

  // ROS 1 serialisation in MCAP (message encoding ros1, schema encoding ros1msg).
  {
    const buffer = new TempBuffer();
    const writer = new McapWriter({ writable: buffer, chunkSize: small });
    await writer.start({ profile: "ros1", library: "livo-lcm test fixture (@mcap/core)" });
    const schemaId = await writer.registerSchema({ name: "sensor_msgs/Imu", encoding: "ros1msg", data: new Uint8Array() });
    const channelId = await writer.registerChannel({ topic: "/imu", messageEncoding: "ros1", schemaId, metadata: new Map() });
    let seq = 0;
    for (const m of ros1Imu)
      await writer.addMessage({ channelId, sequence: seq++, logTime: m.logTime, publishTime: m.logTime, data: m.data });
    await writer.end();
    fs.writeFileSync(path.join(outDir, "ros1_encoded.mcap"), buffer.get());
  }

  const rows = messages.map((m) => ({ topic: m.topic, type: ros2Name(m.type), timestamp: m.logTime.toString(),
                                      data: Buffer.from(m.data).toString("base64") }));
  fs.writeFileSync(path.join(outDir, "rows.json"), JSON.stringify(rows));
  fs.writeFileSync(path.join(outDir, "expected.json"), JSON.stringify(expected, null, 1));
}

/// rosbag2's metadata.yaml (version 5 layout) for the messages above.
function metadataYaml(storage, files, compressionMode = "") {
  const counts = new Map();
  for (const m of messages) counts.set(m.topic, { type: ros2Name(m.type), n: (counts.get(m.topic)?.n ?? 0) + 1 });
  const t0 = messages.reduce((a, m) => (m.logTime < a ? m.logTime : a), messages[0].logTime);
  const t1 = messages.reduce((a, m) => (m.logTime > a ? m.logTime : a), messages[0].logTime);
  let y = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " + storage + "\n";
  y += `  duration:\n    nanoseconds: ${t1 - t0}\n  starting_time:\n    nanoseconds_since_epoch: ${t0}\n`;
  y += `  message_count: ${messages.length}\n  topics_with_message_count:\n`;
  for (const [topic, { type, n }] of counts)
    y += `    - topic_metadata:\n        name: ${topic}\n        type: ${type}\n        serialization_format: cdr\n` +
         `        offered_qos_profiles: ""\n      message_count: ${n}\n`;
  y += compressionMode ? `  compression_format: zstd\n  compression_mode: ${compressionMode}\n`
                      : `  compression_format: ""\n  compression_mode: ""\n`;
  y += "  relative_file_paths:\n";
  for (const f of files) y += `    - ${f}\n`;
  return y;
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
