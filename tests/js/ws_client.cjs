// A Foxglove WebSocket client built on npm's `ws` (not DL-SLOT's code), for the live bridge's
// process test: connects with subprotocol foxglove.websocket.v1, waits for the advertisement,
// subscribes to the given topics and prints, as JSON, what arrived on each.
//   NODE_PATH=BUILD/npm/node_modules node ws_client.cjs URL TOPIC[,TOPIC...] COUNT TIMEOUT_MS [STALL_MS]
// With STALL_MS the client stops reading its socket for that long after subscribing (a viewer
// that cannot keep up), then reads on.
"use strict";
const WebSocket = require("ws");

const [url, topicList, countText, timeoutText, stallText] = process.argv.slice(2);
const wanted = topicList.split(",");
const count = Number(countText);
const report = { serverInfo: null, advertised: {}, statuses: [], topics: {}, errors: [] };
for (const t of wanted) report.topics[t] = { received: 0, details: [] };
const topicOfSubscription = new Map();

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
  const msg = JSON.parse(buf.subarray(13).toString());
  const entry = report.topics[topic];
  ++entry.received;
  if (msg.data !== undefined) entry.details.push({ points: Buffer.from(msg.data, "base64").length / msg.point_stride });
  else if (msg.entities !== undefined) entry.details.push({ entities: msg.entities.length, texts: msg.entities.map((e) => e.texts[0]?.text) });
  else entry.details.push({});
  if (wanted.every((t) => report.topics[t].received >= count)) {
    ws.close();
    finish(0);
  }
});
