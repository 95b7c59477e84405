// Counts what a Foxglove WebSocket client receives per topic without decoding it (a viewer on
// another machine), to measure the live bridge's cost to the pipeline; prints the counts, the bytes
// and its own CPU time (ms):
//   NODE_PATH=build/npm/node_modules node tests/js/ws_count.cjs ws://127.0.0.1:PORT /lidar/points,/slot/tracks SECONDS
"use strict";
const WebSocket = require("ws");
const [url, topicList, seconds] = process.argv.slice(2);
const wanted = topicList.split(",");
const counts = {}; const bytes = {};
const sub = new Map();
function done() {
  const cpu = process.cpuUsage();
  console.log(JSON.stringify({ counts, bytes, cpu_ms: Math.round((cpu.user + cpu.system) / 1000) }));
  process.exit(0);
}
setTimeout(done, Number(seconds) * 1000);
function connect() {
  const ws = new WebSocket(url, ["foxglove.websocket.v1"]);
  let opened = false;
  ws.on("open", () => { opened = true; });
  ws.on("error", () => { if (!opened) setTimeout(connect, 200); });
  ws.on("close", () => { if (opened) done(); });
  ws.on("message", (data, isBinary) => {
    if (!isBinary) {
      const msg = JSON.parse(data.toString());
      if (msg.op !== "advertise") return;
      const subs = [];
      for (const c of msg.channels) if (wanted.includes(c.topic)) { const id = 100 + subs.length; sub.set(id, c.topic); subs.push({ id, channelId: c.id }); }
      ws.send(JSON.stringify({ op: "subscribe", subscriptions: subs }));
      return;
    }
    const t = sub.get(data.readUInt32LE(1)); counts[t] = (counts[t] || 0) + 1; bytes[t] = (bytes[t] || 0) + data.length;
  });
}
connect();
