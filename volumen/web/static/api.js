// Talking to the server (volumen/web/_server.py): JSON routes and the binary messages of _frames.py
// (b"VOLW", uint32 header length, JSON header, arrays at multiples of 8). Requests carry the token of the
// page's URL as a header; the module files themselves come with the cookie the server set.

/** @typedef {Float32Array | Uint8Array | Uint16Array | Int32Array} TypedArray */
/** @typedef {{data: TypedArray, shape: number[]}} WireArray  an array of a message (float16: its bits, Uint16Array) */
/** @typedef {Record<string, WireArray>} Arrays */
/** @typedef {{header: Record<string, unknown>, arrays: Arrays}} Message */
/** @typedef {Record<string, string | number>} Params  a request's query parameters */

const TOKEN = new URLSearchParams(location.search).get('token');
/** @type {Record<string, string>} */
const HEADERS = TOKEN ? { 'X-Volumen-Token': TOKEN } : {};
/** @typedef {{new (buf: ArrayBuffer, offset: number, length: number): TypedArray, BYTES_PER_ELEMENT: number}} Typed */
/** @type {Record<string, Typed>} the arrays' classes by their dtype */
const TYPES = { float32: Float32Array, uint8: Uint8Array, float16: Uint16Array, int32: Int32Array };

/** @param {Response} response @returns {Promise<Response>} */
async function checked(response) {
  if (!response.ok) throw new Error(`${response.status}: ${(await response.text()).slice(0, 300)}`);
  return response;
}

/** @param {Params} [params] */
const query = (params) => (params ? '?' + new URLSearchParams(Object.entries(params).map(([k, v]) => [k, String(v)]))
  : '');

/** @param {string} route @param {Params} [params] @returns {Promise<any>} the parsed JSON */
export async function getJSON(route, params) {
  return (await checked(await fetch(route + query(params), { headers: HEADERS }))).json();
}

/** @param {string} route @param {Params} [params] @returns {Promise<Message>} */
export async function getBinary(route, params) {
  return decode(await (await checked(await fetch(route + query(params), { headers: HEADERS }))).arrayBuffer());
}

/** @param {string} route @param {unknown} body sent as JSON @returns {Promise<Message>} */
export async function postBinary(route, body) {
  const r = await fetch(route, { method: 'POST', headers: { ...HEADERS, 'Content-Type': 'application/json' },
    body: JSON.stringify(body) });
  return decode(await (await checked(r)).arrayBuffer());
}

/** @param {string} route @param {unknown} body sent as JSON @returns {Promise<any>} the parsed JSON answer */
export async function postJSON(route, body) {
  const r = await fetch(route, { method: 'POST', headers: { ...HEADERS, 'Content-Type': 'application/json' },
    body: JSON.stringify(body) });
  return (await checked(r)).json();
}

// a slice picture (an object URL of the PNG), its pixel -> world map and where the other planes cut it
/**
 * @typedef {object} Slice
 * @property {string} url
 * @property {number[][]} map  the world point of the picture's pixel (0, 0), and its steps along a column and a row
 * @property {{row: number, col: number, row_plane: string, col_plane: string}} cross  the pixel row and column
 *   where the other two planes cut the picture, and which plane each is
 */
/** @param {Params} params @returns {Promise<Slice>} */
export async function getSlice(params) {
  const r = await checked(await fetch('slice.png' + query(params), { headers: HEADERS }));
  const header = (/** @type {string} */ name) => JSON.parse(r.headers.get(name) ?? 'null');
  return { url: URL.createObjectURL(await r.blob()), map: header('X-Slice-Map'), cross: header('X-Slice-Cross') };
}

// {header, arrays: {name: {data: TypedArray, shape}}}
/** @param {ArrayBuffer} buf @returns {Message} */
export function decode(buf) {
  const bytes = new Uint8Array(buf);
  if (String.fromCharCode(...bytes.subarray(0, 4)) !== 'VOLW') throw new Error('not a volumen message');
  const n = new DataView(buf).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(8, 8 + n)));
  const base = 8 + n;
  /** @type {Arrays} */
  const arrays = {};
  /** @type {Record<string, {dtype: string, offset: number, nbytes: number, shape: number[]}>} */
  const table = header.arrays;
  for (const [name, d] of Object.entries(table)) {
    const T = TYPES[d.dtype];
    arrays[name] = { data: new T(buf, base + d.offset, d.nbytes / T.BYTES_PER_ELEMENT), shape: d.shape };
  }
  delete header.arrays;
  return { header, arrays };
}
