// Loads an FBX file with three.js's FBXLoader under node and plays its first animation with an
// AnimationMixer: prints, as JSON, the bones by name, the animations, and every bone's world
// position at the requested times (seconds). three.js keeps the file's units (Mixamo's and
// Blender's centimetres) and sanitises names as PropertyBinding does.
// Usage: node three_fbx_positions.mjs FILE.fbx T1,T2,...
import { readFile } from "node:fs/promises";
import * as THREE from "three";
import { FBXLoader } from "three/addons/loaders/FBXLoader.js";

const [file, timesArg] = process.argv.slice(2);
const times = timesArg.split(",").map(Number);
const bytes = await readFile(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const group = new FBXLoader().parse(buffer, "");
const bones = [];
group.traverse((o) => {
  if (o.isBone) bones.push(o);
});
const out = {
  bones: bones.map((b) => b.name),
  animations: group.animations.map((a) => ({
    name: a.name,
    duration: a.duration,
    tracks: a.tracks.length,
    firstKey: Math.min(...a.tracks.map((t) => t.times[0])),
  })),
  positions: [],
};
const v = new THREE.Vector3();
for (const clip of group.animations) {
  const mixer = new THREE.AnimationMixer(group);
  mixer.clipAction(clip).play();
  const perTime = [];
  for (const t of times) {
    mixer.setTime(t);
    group.updateMatrixWorld(true);
    perTime.push(bones.map((b) => b.getWorldPosition(v).toArray()));
  }
  out.positions.push(perTime);
  mixer.stopAllAction();
}
console.log(JSON.stringify(out));
