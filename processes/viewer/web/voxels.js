// The cloud as coloured voxels (the page's "voxels" toggle): the mapper's map_colour.ot colours
// every occupied OctoMap voxel by the worst accuracy level among the points in it; this draws the
// same rule on the points the page holds (the mapper's preview, one point per 5 cm cell it first
// fell in), on a coarser grid aligned with the OctoMap's (voxel_m, from the viewer's config: nodes
// eight of the mapper's 2 cm leaves wide), as one instanced box per voxel. Worst, not newest: a
// voxel seen on the way out and again after an unclosed loop shows the poorer estimate. It is
// rebuilt from the points as they are now (after loop closures moved them) at most once a second
// while shown, so it costs nothing while hidden.
import * as THREE from 'three';

const GRID = 65536;  // voxel indices per axis: +-32768 voxels, the OctoMap's key range
const HALF = GRID / 2;

export class Voxels {
  // cloud: the page's Cloud (positions, profiles with their level); colourOf(level): [r, g, b].
  constructor(scene, cloud, colourOf) {
    this.cloud = cloud;
    this.colourOf = colourOf;
    this.size = 0.16;  // [m] until the viewer says
    this.capacity = 0;
    this.count = 0;
    this.levelCounts = {};  // voxels per level index (-1: no annotation yet)
    this.material = new THREE.MeshBasicMaterial();
    this.mesh = null;
    this.scene = scene;
    this.visible = false;
    this.stale = true;
    this.builtAt = 0;
  }
  setSize(size) {
    if (size === this.size) return;
    this.size = size;
    this.capacity = 0;  // a new box
    this.stale = true;
  }
  show(on) {
    this.visible = on;
    if (this.mesh) this.mesh.visible = on;
    this.stale = true;
  }
  // Returns true when it drew anew (the caller renders).
  update(now) {
    if (!this.visible || !this.stale || now - this.builtAt < 1000) return false;
    this.stale = false;
    this.builtAt = now;
    this.build();
    return true;
  }
  build() {
    const worst = new Map();  // packed voxel index -> worst level of its points
    const pos = this.cloud.positions, inv = 1 / this.size;
    for (const p of this.cloud.profiles.values()) {
      for (let i = p.offset * 3, end = (p.offset + p.n) * 3; i < end; i += 3) {
        const kx = Math.floor(pos[i] * inv) + HALF, ky = Math.floor(pos[i + 1] * inv) + HALF;
        const kz = Math.floor(pos[i + 2] * inv) + HALF;
        if (kx < 0 || ky < 0 || kz < 0 || kx >= GRID || ky >= GRID || kz >= GRID) continue;
        const key = (kx * GRID + ky) * GRID + kz;  // under 2^48: exact in a double
        const held = worst.get(key);
        if (held === undefined || p.level > held) worst.set(key, p.level);
      }
    }
    if (worst.size > this.capacity) this.grow(Math.max(worst.size, this.capacity * 2, 1024));
    const m = new THREE.Matrix4(), c = new THREE.Color();
    const counts = {};
    let n = 0;
    for (const [key, level] of worst) {
      const kz = key % GRID, kxy = (key - kz) / GRID, ky = kxy % GRID, kx = (kxy - ky) / GRID;
      m.makeTranslation((kx - HALF + 0.5) * this.size, (ky - HALF + 0.5) * this.size,
        (kz - HALF + 0.5) * this.size);
      this.mesh.setMatrixAt(n, m);
      const rgb = this.colourOf(level);
      this.mesh.setColorAt(n, c.setRGB(rgb[0], rgb[1], rgb[2]));
      counts[level] = (counts[level] || 0) + 1;
      ++n;
    }
    this.count = n;
    this.levelCounts = counts;
    this.mesh.count = n;
    this.mesh.instanceMatrix.needsUpdate = true;
    if (this.mesh.instanceColor) this.mesh.instanceColor.needsUpdate = true;
  }
  grow(capacity) {
    if (this.mesh) {
      this.scene.remove(this.mesh);
      this.mesh.geometry.dispose();
      this.mesh.dispose();
    }
    // Slightly smaller than the voxel, so neighbours stay apart on the screen.
    const s = this.size * 0.9;
    this.mesh = new THREE.InstancedMesh(new THREE.BoxGeometry(s, s, s), this.material, capacity);
    this.mesh.frustumCulled = false;
    this.mesh.visible = this.visible;
    this.capacity = capacity;
    this.scene.add(this.mesh);
  }
}
