// Loads a GLB with three.js's GLTFLoader under node and plays each animation with an
// AnimationMixer: prints, as JSON, the bones (skin joints) by name, the animations, and every
// bone's world position at the requested times (seconds) of each animation.
// Usage: node three_positions.mjs FILE.glb T1,T2,...
import { readFile } from "node:fs/promises";
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

const [file, timesArg] = process.argv.slice(2);
const times = timesArg.split(",").map(Number);
const bytes = await readFile(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const gltf = await new Promise((resolve, reject) =>
  new GLTFLoader().parse(buffer, "", resolve, reject),
);
const bones = [];
gltf.scene.traverse((o) => {
  if (o.isBone) bones.push(o);
});
const out = {
  bones: bones.map((b) => b.name),
  parents: bones.map((b) => (b.parent && b.parent.isBone ? b.parent.name : null)),
  animations: gltf.animations.map((a) => ({ name: a.name, duration: a.duration, tracks: a.tracks.length })),
  positions: [],
};
const v = new THREE.Vector3();
for (const clip of gltf.animations) {
  const mixer = new THREE.AnimationMixer(gltf.scene);
  mixer.clipAction(clip).play();
  const perTime = [];
  for (const t of times) {
    mixer.setTime(t);
    gltf.scene.updateMatrixWorld(true);
    perTime.push(bones.map((b) => b.getWorldPosition(v).toArray()));
  }
  out.positions.push(perTime);
  mixer.stopAllAction();
}
console.log(JSON.stringify(out));
