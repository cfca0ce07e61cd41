// Converts a ROS 1 bag into a ROS 2 bag with other implementations than livo-import: the ROS 1 bag
// read by @foxglove/rosbag (chunk by chunk, each chunk's messages in file order from its index
// records: messages with equal receive times keep the order the recorder wrote them in, as in a
// real conversion), parsed by @foxglove/rosmsg-serialization, each message mapped field by field onto its
// ROS 2 Humble definition (@foxglove/rosmsg-msgs-common: header without seq, time as sec /
// nanosec, CameraInfo's D K R P as d k r p), serialised to CDR by @foxglove/rosmsg2-serialization
// and written by @mcap/core's McapWriter (zstd chunks by @foxglove/wasm-zstd). Messages keep the
// ROS 1 bag's order and receive times.
//
//   node ros1_to_rosbag2.js IN.bag OUT.mcap [--rows ROWS.json]
//
// --rows also writes the CDR messages as make_rosbag2_db3.py reads them (for a .db3 of the bag).
"use strict";

const fs = require("fs");
const { Bag } = require("@foxglove/rosbag");
const { FileReader } = require("@foxglove/rosbag/node");
const { MessageData } = require("@foxglove/rosbag/dist/cjs/record");
const { MessageReader } = require("@foxglove/rosmsg-serialization");
const { parse } = require("@foxglove/rosmsg");
const { McapWriter, TempBuffer } = require("@mcap/core");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const { ros2humble } = require("@foxglove/rosmsg-msgs-common");
const zstd = require("@foxglove/wasm-zstd");

const [input, output, rowsFlag, rowsPath] = process.argv.slice(2);
if (!input || !output || (rowsFlag && (rowsFlag !== "--rows" || !rowsPath))) {
  console.error("usage: node ros1_to_rosbag2.js IN.bag OUT.mcap [--rows ROWS.json]");
  process.exit(2);
}

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

/// A parsed ROS 1 value as the ROS 2 definition of `type` wants it.
function toRos2(value, type) {
  const out = {};
  for (const f of ros2humble[type].definitions) {
    if (f.isConstant) continue;
    let v = value[f.name];
    if (v === undefined) v = value[f.name.toUpperCase()];  // CameraInfo: D K R P -> d k r p
    if (v === undefined) throw new Error(`${type}.${f.name}: no such field in the ROS 1 message`);
    if (f.type === "time" || f.type === "duration")
      out[f.name] = f.isArray ? v.map((t) => ({ sec: t.sec, nanosec: t.nsec })) : { sec: v.sec, nanosec: v.nsec };
    else if (f.isComplex) out[f.name] = f.isArray ? v.map((x) => toRos2(x, f.type)) : toRos2(v, f.type);
    else out[f.name] = v;
  }
  return out;
}

async function main() {
  await zstd.isLoaded;
  const bag = new Bag(new FileReader(input));
  await bag.open();
  const buffer = new TempBuffer();
  const writer = new McapWriter({
    writable: buffer, chunkSize: 4 << 20,
    compressChunk: (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 1) }) });
  await writer.start({ profile: "ros2", library: "livo-lcm test tooling (@mcap/core)" });
  const channels = new Map();
  const serializers = new Map();
  const rows = [];
  const readers = new Map();
  let seq = 0;
  const chunks = [...bag.chunkInfos].sort((a, b) => a.chunkPosition - b.chunkPosition);
  for (const chunkInfo of chunks) {
    const { chunk, indices } = await bag.reader.readChunk(chunkInfo, {});
    const offsets = indices.flatMap((ix) => ix.indices.map((e) => e.offset)).sort((a, b) => a - b);
    for (const offset of offsets) {
      const record = bag.reader.readRecordFromBuffer(chunk.data.subarray(offset), chunk.dataOffset, MessageData);
      const conn = bag.connections.get(record.conn);
      const type = conn.type;  // "sensor_msgs/Imu"
      const ros2Type = type.replace("/", "/msg/");
      if (!channels.has(conn.topic)) {
        const schemaId = await writer.registerSchema({ name: ros2Type, encoding: "ros2msg", data: new Uint8Array() });
        channels.set(conn.topic, await writer.registerChannel({ topic: conn.topic, messageEncoding: "cdr", schemaId,
                                                                metadata: new Map() }));
        serializers.set(conn.topic, new MessageWriter(definitionsOf(type)));
        readers.set(conn.topic, new MessageReader(parse(conn.messageDefinition)));
      }
      const message = readers.get(conn.topic).readMessage(record.data);
      const data = serializers.get(conn.topic).writeMessage(toRos2(message, type));
      const logTime = BigInt(record.time.sec) * 1000000000n + BigInt(record.time.nsec);
      await writer.addMessage({ channelId: channels.get(conn.topic), sequence: seq++, logTime, publishTime: logTime,
                                data });
      if (rowsPath)
        rows.push({ topic: conn.topic, type: ros2Type, timestamp: logTime.toString(),
                    data: Buffer.from(data).toString("base64") });
    }
  }
  await writer.end();
  fs.writeFileSync(output, buffer.get());
  if (rowsPath) fs.writeFileSync(rowsPath, JSON.stringify(rows));
  console.error(`ros1_to_rosbag2: ${seq} messages on ${channels.size} topics -> ${output}`);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
