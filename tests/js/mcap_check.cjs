// Reads an MCAP file with @mcap/core (Foxglove's own TypeScript reader, not DL-SLOT's code) and
// prints what it found as JSON, for tests/foxglove_mcap_test.cpp to compare with the LCM log:
// every channel's schema, message count and message timestamps, read twice (streamed from the
// start with chunk CRCs checked, and through the summary's indexes), plus the data-section and
// summary CRCs recomputed with node's zlib.
//   NODE_PATH=BUILD/npm/node_modules node mcap_check.cjs FILE.mcap
"use strict";
const { readFileSync } = require("node:fs");
// node >= 20.15 has zlib.crc32; Debian 12's node 18 does not: the same CRC-32 from its table then.
const crc32 = require("node:zlib").crc32 ?? ((bytes) => {
  const table = new Uint32Array(256).map((_, n) => {
    let c = n;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    return c >>> 0;
  });
  let crc = 0xffffffff;
  for (const b of bytes) crc = table[(crc ^ b) & 0xff] ^ (crc >>> 8);
  return (crc ^ 0xffffffff) >>> 0;
});
const { McapStreamReader, McapIndexedReader } = require("@mcap/core");

async function main() {

const path = process.argv[2];
const bytes = new Uint8Array(readFileSync(path));
const errors = [];
const decoder = new TextDecoder();

function stampNs(t) {
  if (!t || typeof t.sec !== "number" || typeof t.nsec !== "number") return null;
  return (BigInt(t.sec) * 1000000000n + BigInt(t.nsec)).toString();
}

// What a message of each schema must hold, beyond being JSON.
function checkMessage(schemaName, msg, topic) {
  switch (schemaName) {
    case "foxglove.PointCloud": {
      const data = Buffer.from(msg.data, "base64");
      if (msg.point_stride !== 16 || msg.fields.length !== 4 || data.length % msg.point_stride !== 0)
        errors.push(`${topic}: point cloud layout: stride ${msg.point_stride}, ${data.length} bytes`);
      return { points: data.length / msg.point_stride, first: data.length >= 16 ? [0, 4, 8, 12].map((o) => data.readFloatLE(o)) : [] };
    }
    case "foxglove.SceneUpdate":
      for (const e of msg.entities) {
        // A box is one cube, a loop one line; each has one label.
        if (e.cubes.length + e.lines.length === 0 || e.cubes.length > 1 || e.texts.length !== 1)
          errors.push(`${topic}: entity ${e.id} lacks its cube (or line) or text`);
      }
      return { entities: msg.entities.length, lines: msg.entities.reduce((n, e) => n + e.lines.length, 0),
               texts: msg.entities.map((e) => e.texts[0]?.text) };
    case "foxglove.FrameTransform":
      return { parent: msg.parent_frame_id, child: msg.child_frame_id, t: [msg.translation.x, msg.translation.y, msg.translation.z] };
    case "foxglove.PosesInFrame":
      return { poses: msg.poses.length, frame: msg.frame_id };
    default:
      return {};
  }
}

const topics = {};
function topicEntry(channel, schema) {
  const t = (topics[channel.topic] ??= {
    schemaName: schema?.name ?? "", schemaEncoding: schema?.encoding ?? "", messageEncoding: channel.messageEncoding,
    schemaTitle: null, streamed: 0, indexed: 0, timestamps: [], logTimes: [], details: [],
  });
  if (schema && t.schemaTitle === null) {
    try { t.schemaTitle = JSON.parse(decoder.decode(schema.data)).title; } catch (e) { errors.push(`${channel.topic}: schema is not JSON: ${e}`); }
  }
  return t;
}

// 1. Streamed, chunk CRCs validated.
const stream = new McapStreamReader({ validateCrcs: true });
stream.append(bytes);
const schemas = new Map(), channels = new Map();
let header = null, dataEndCrc = null, footer = null, statistics = null, chunkIndexes = 0, records = 0;
for (let r; (r = stream.nextRecord()); ) {
  ++records;
  switch (r.type) {
    case "Header": header = { profile: r.profile, library: r.library }; break;
    case "Schema": schemas.set(r.id, r); break;
    case "Channel": channels.set(r.id, r); break;
    case "Message": {
      const ch = channels.get(r.channelId);
      if (!ch) { errors.push(`message on unknown channel ${r.channelId}`); break; }
      const t = topicEntry(ch, schemas.get(ch.schemaId));
      ++t.streamed;
      let msg;
      try { msg = JSON.parse(decoder.decode(r.data)); } catch (e) { errors.push(`${ch.topic}: message is not JSON: ${e}`); break; }
      // A SceneUpdate has no stamp of its own: its deletion (and every entity) carries the scan's.
      t.timestamps.push(stampNs(msg.timestamp ?? msg.deletions?.[0]?.timestamp));
      t.logTimes.push(r.logTime.toString());
      t.details.push(checkMessage(t.schemaName, msg, ch.topic));
      break;
    }
    case "DataEnd": dataEndCrc = r.dataSectionCrc; break;
    case "Statistics": statistics = r; break;
    case "ChunkIndex": ++chunkIndexes; break;
    case "Footer": footer = r; break;
  }
}
if (!stream.done()) errors.push("the stream reader did not reach a valid footer");

// 2. The CRCs the stream reader does not check, recomputed here.
const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
const footerAt = bytes.length - 8 - (1 + 8 + 20);
let dataCrcOk = false, summaryCrcOk = false;
if (footer) {
  const summaryStart = Number(footer.summaryStart);
  const dataEndAt = summaryStart - (1 + 8 + 4);
  dataCrcOk = crc32(bytes.subarray(0, dataEndAt)) === dataEndCrc;
  summaryCrcOk = crc32(bytes.subarray(summaryStart, footerAt + 1 + 8 + 16)) === view.getUint32(footerAt + 1 + 8 + 16, true);
}

// 3. Through the index (summary, chunk indexes, message indexes).
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};
const indexed = await McapIndexedReader.Initialize({ readable });
for await (const m of indexed.readMessages({ validateCrcs: true })) {
  const ch = indexed.channelsById.get(m.channelId);
  topicEntry(ch, indexed.schemasById.get(ch.schemaId)).indexed++;
}
const channelCounts = {};
for (const [id, n] of indexed.statistics?.channelMessageCounts ?? []) channelCounts[indexed.channelsById.get(id).topic] = Number(n);

console.log(JSON.stringify({
  header, records, dataCrcOk, summaryCrcOk, chunkIndexes,
  chunkCount: indexed.statistics?.chunkCount, messageCount: Number(indexed.statistics?.messageCount ?? -1),
  channelCounts, topics, errors,
}));
}

main().catch((e) => {
  console.error(`mcap_check: ${e.stack ?? e}`);
  process.exit(1);
});
