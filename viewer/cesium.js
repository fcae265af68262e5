// The build in CesiumJS (`/viewer/cesium.html?h=K` under `edo-city serve`): the same 3D Tiles
// 1.1 tileset the three.js viewer loads, on a plain ellipsoid with no imagery and no Cesium
// ion token, so it works offline. Clicking an object shows its metadata row in Cesium's
// info box. For tests and scripts, `window.edoCesium` reports when the view is loaded, the
// tileset's centre in longitude, latitude and height, the tile errors and what a pick names.
/* global Cesium */

const api = (window.edoCesium = {
  ready: false,
  errors: [],
  centre: null,
  tilesLoaded: 0,
  // The metadata of the object drawn at a pixel (x, y from the top left), or null.
  pick: (x, y) => pick(x, y),
});
const status = document.getElementById('status');

function pick(x, y) {
  const feature = viewer.scene.pick(new Cesium.Cartesian2(x, y));
  if (!(feature instanceof Cesium.Cesium3DTileFeature)) return null;
  const row = {};
  for (const id of feature.getPropertyIds()) row[id] = feature.getProperty(id);
  return row;
}

Cesium.Ion.defaultAccessToken = '';
const viewer = new Cesium.Viewer('globe', {
  baseLayer: false,
  baseLayerPicker: false,
  geocoder: false,
  homeButton: false,
  sceneModePicker: false,
  navigationHelpButton: false,
  animation: false,
  timeline: false,
  fullscreenButton: false,
  terrainProvider: new Cesium.EllipsoidTerrainProvider(),
});
viewer.scene.globe.baseColor = Cesium.Color.fromCssColorString('#8a7f6a');
viewer.scene.backgroundColor = Cesium.Color.fromCssColorString('#bcd6ea');

async function main() {
  const query = new URLSearchParams(location.search);
  const h = Number(query.get('h') ?? 0);
  const tileset = await Cesium.Cesium3DTileset.fromUrl(`/h/${h}/tileset.json`);
  // `?sse=N`: Cesium's screen-space error target (16 pixels by default); a small one loads
  // the leaves of a small town from its overview (the tests read walkers and instanced trees).
  if (query.has('sse')) tileset.maximumScreenSpaceError = Number(query.get('sse'));
  tileset.tileFailed.addEventListener((e) => api.errors.push(`${e.url}: ${e.message}`));
  tileset.tileLoad.addEventListener(() => {
    api.tilesLoaded += 1;
  });
  viewer.scene.primitives.add(tileset);
  const c = Cesium.Cartographic.fromCartesian(tileset.boundingSphere.center);
  api.centre = [Cesium.Math.toDegrees(c.longitude), Cesium.Math.toDegrees(c.latitude), c.height];
  await viewer.zoomTo(tileset, new Cesium.HeadingPitchRange(0, Cesium.Math.toRadians(-50), 0));
  // Ready once the view's tiles are in (Cesium tells each time the queue empties).
  tileset.allTilesLoaded.addEventListener(() => {
    api.ready = true;
    status.textContent = `tiles loaded: ${api.tilesLoaded}`;
  });
}

main().catch((e) => {
  api.errors.push(e.message);
  status.textContent = `error: ${e.message}`;
  console.error(e);
});
