// Reads run.mcap files with Foxglove's MCAP reader (@mcap/core, indexed as the Foxglove app reads a file)
// and checks every message on a channel with a Foxglove schema (foxglove.SceneUpdate, FrameTransforms, Log)
// against Foxglove's own JSON Schemas (@foxglove/schemas/jsonschema); prints the scene's entities and frames.
// Needs: npm install @mcap/core @mcap/nodejs @mcap/support @foxglove/schemas ajv
// Usage: node scripts/mcap_scene_check.mjs RUN_DIR/run.mcap ...   (exit 1 if a message does not conform)
import { McapIndexedReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";
import * as schemas from "@foxglove/schemas/jsonschema.js";
import AjvModule from "ajv";
import { open } from "node:fs/promises";

const Ajv = AjvModule.default ?? AjvModule;
const ajv = new Ajv({ strict: false, allErrors: false });
const validators = {};
for (const s of Object.values(schemas)) {
  if (s && typeof s === "object" && typeof s.title === "string") validators[s.title] = ajv.compile(s);
}
const decompressHandlers = await loadDecompressHandlers();
let bad = 0;
for (const path of process.argv.slice(2)) {
  const fh = await open(path, "r");
  const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(fh), decompressHandlers });
  const perTopic = {};
  const entities = new Set();
  const frames = new Set();
  let muscleLines = 0;
  for await (const msg of reader.readMessages()) {
    const ch = reader.channelsById.get(msg.channelId);
    const schema = reader.schemasById.get(ch.schemaId);
    const validate = schema && validators[schema.name];
    if (!validate) continue;
    const data = JSON.parse(new TextDecoder().decode(msg.data));
    const t = (perTopic[ch.topic] ??= { schema: schema.name, messages: 0, invalid: 0 });
    t.messages += 1;
    if (!validate(data)) {
      t.invalid += 1;
      bad += 1;
      if (t.invalid === 1) console.log(`${ch.topic}: ${ajv.errorsText(validate.errors)}`);
    }
    for (const e of data.entities ?? []) {
      entities.add(`${e.id} (frame ${e.frame_id}: ${["cubes", "spheres", "cylinders", "lines", "triangles"]
        .filter((k) => e[k]?.length).map((k) => `${e[k].length} ${k}`).join(", ")})`);
      if (e.id === "muscles") muscleLines = e.lines.length;
    }
    for (const x of data.transforms ?? []) frames.add(`${x.parent_frame_id}->${x.child_frame_id}`);
  }
  await fh.close();
  console.log(path);
  console.log("  channels with Foxglove schemas:", JSON.stringify(perTopic));
  console.log("  entities:", [...entities].sort().join("; "));
  console.log("  frames:", [...frames].join(" "));
  if (muscleLines) console.log("  muscle lines:", muscleLines);
}
process.exit(bad ? 1 : 0);
