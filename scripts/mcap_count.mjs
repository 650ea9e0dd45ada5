import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";
import { open, readFile } from "node:fs/promises";
const decompressHandlers = await loadDecompressHandlers();
for (const path of process.argv.slice(2)) {
  const counts = {};
  let how = "indexed";
  try {
    const fh = await open(path, "r");
    const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(fh), decompressHandlers });
    for await (const msg of reader.readMessages()) {
      const topic = reader.channelsById.get(msg.channelId).topic;
      JSON.parse(new TextDecoder().decode(msg.data));
      counts[topic] = (counts[topic] ?? 0) + 1;
    }
    await fh.close();
  } catch (err) {
    how = `stream (indexed failed: ${err.message.slice(0, 60)})`;
    const stream = new McapStreamReader({ decompressHandlers });
    stream.append(await readFile(path));
    const topics = new Map();
    let rec;
    try { while ((rec = stream.nextRecord())) {
      if (rec.type === "Channel") topics.set(rec.id, rec.topic);
      if (rec.type === "Message") {
        const t = topics.get(rec.channelId);
        JSON.parse(new TextDecoder().decode(rec.data));
        counts[t] = (counts[t] ?? 0) + 1;
      }
    } } catch (err) { how += `; stopped at the incomplete tail: ${err.message.slice(0, 50)}`; }
  }
  console.log(path, how, JSON.stringify(counts));
}
