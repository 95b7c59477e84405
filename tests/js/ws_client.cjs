// A Foxglove WebSocket client built on npm's `ws` (not DL-SLOT's code), for the live bridge's
// process test: connects with subprotocol foxglove.websocket.v1, waits for the advertisement,
// subscribes to the given topics and prints, as JSON, what arrived on each. Messages of "ros1"
// channels are decoded with Foxglove's ROS 1 reader (@foxglove/rosmsg parses the advertised
// message definition, @foxglove/rosmsg-serialization reads the bytes), those of "json" channels
// with JSON.parse; point clouds are read through their declared fields.
//   NODE_PATH=BUILD/npm/node_modules node ws_client.cjs URL TOPIC[,TOPIC...] COUNT TIMEOUT_MS [STALL_MS]
// With STALL_MS the client stops reading its socket for that long after subscribing (a viewer
// that cannot keep up), then reads on.
"use strict";
const WebSocket = require("ws");
const { parse: parseRosmsg } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg-serialization");

const [url, topicList, countText, timeoutText, stallText] = process.argv.slice(2);
const wanted = topicList.split(",");
const count = Number(countText);
const report = { serverInfo: null, advertised: {}, statuses: [], topics: {}, errors: [] };
for (const t of wanted) report.topics[t] = { received: 0, details: [] };
const topicOfSubscription = new Map();
const decoderOfTopic = new Map();

// The points of a point cloud as [x, y, z, intensity] rows, read through its field list.
function pointsOf(bytes, stride, fields) {
  const offset = {};
  for (const f of fields) offset[f.name] = f.offset;
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const at = (i) => ["x", "y", "z", "intensity"].map((n) => view.getFloat32(i * stride + offset[n], true));
  const n = bytes.byteLength / stride;
  return { points: n, first: n > 0 ? at(0) : [], last: n > 0 ? at(n - 1) : [] };
}

function finish(code) {
  console.log(JSON.stringify(report));
  process.exit(code);
}
setTimeout(() => { report.errors.push("timed out"); finish(1); }, Number(timeoutText));

const ws = new WebSocket(url, ["foxglove.websocket.v1"]);
ws.on("error", (e) => { report.errors.push(String(e)); finish(1); });
ws.on("message", (data, isBinary) => {
  if (!isBinary) {
    const msg = JSON.parse(data.toString());
    if (msg.op === "serverInfo") report.serverInfo = msg;
    else if (msg.op === "status") report.statuses.push(msg);
    else if (msg.op === "advertise") {
      const subscriptions = [];
      for (const c of msg.channels) {
        report.advertised[c.topic] = { id: c.id, schemaName: c.schemaName, encoding: c.encoding, schemaEncoding: c.schemaEncoding };
        if (wanted.includes(c.topic)) {
          if (c.encoding === "ros1") {
            const reader = new MessageReader(parseRosmsg(c.schema, { ros2: false }));
            decoderOfTopic.set(c.topic, (bytes) => reader.readMessage(bytes));
          } else {
            decoderOfTopic.set(c.topic, (bytes) => JSON.parse(Buffer.from(bytes).toString()));
          }
          const id = 100 + subscriptions.length;
          topicOfSubscription.set(id, c.topic);
          subscriptions.push({ id, channelId: c.id });
        }
      }
      ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
      if (stallText) {
        ws._socket.pause();
        setTimeout(() => ws._socket.resume(), Number(stallText));
      }
    }
    return;
  }
  const buf = Buffer.from(data);
  if (buf[0] !== 1) { report.errors.push(`binary opcode ${buf[0]}`); return; }
  const topic = topicOfSubscription.get(buf.readUInt32LE(1));
  if (!topic) { report.errors.push(`unknown subscription ${buf.readUInt32LE(1)}`); return; }
  let msg;
  try {
    msg = decoderOfTopic.get(topic)(buf.subarray(13));
  } catch (e) {
    report.errors.push(`${topic}: does not decode: ${e}`);
    return;
  }
  const entry = report.topics[topic];
  ++entry.received;
  if (msg.point_step !== undefined) {  // sensor_msgs/PointCloud2
    const d = pointsOf(msg.data, msg.point_step, msg.fields);
    if (d.points !== msg.width * msg.height) report.errors.push(`${topic}: ${d.points} points in data, width ${msg.width}`);
    entry.details.push({ ...d, frame_id: msg.header.frame_id, stamp: [msg.header.stamp.sec, msg.header.stamp.nsec],
                         seq: msg.header.seq, fields: msg.fields.map((f) => [f.name, f.offset, f.datatype, f.count]),
                         is_bigendian: msg.is_bigendian, is_dense: msg.is_dense });
  } else if (msg.data !== undefined) {  // foxglove.PointCloud (JSON)
    entry.details.push(pointsOf(Buffer.from(msg.data, "base64"), msg.point_stride, msg.fields));
  } else if (msg.entities !== undefined) entry.details.push({ entities: msg.entities.length, texts: msg.entities.map((e) => e.texts[0]?.text) });
  else entry.details.push({});
  if (wanted.every((t) => report.topics[t].received >= count)) {
    ws.close();
    finish(0);
  }
});
