// Talking to the server (volumen/web/_server.py): JSON routes and the binary messages of _frames.py
// (b"VOLW", uint32 header length, JSON header, arrays at multiples of 8). Requests carry the token of the
// page's URL as a header; the module files themselves come with the cookie the server set.

const TOKEN = new URLSearchParams(location.search).get('token');
const HEADERS = TOKEN ? { 'X-Volumen-Token': TOKEN } : {};
const TYPES = { float32: Float32Array, uint8: Uint8Array, float16: Uint16Array, int32: Int32Array };

async function checked(response) {
  if (!response.ok) throw new Error(`${response.status}: ${(await response.text()).slice(0, 300)}`);
  return response;
}

const query = (params) => (params ? '?' + new URLSearchParams(params) : '');

export async function getJSON(route, params) {
  return (await checked(await fetch(route + query(params), { headers: HEADERS }))).json();
}

export async function getBinary(route, params) {
  return decode(await (await checked(await fetch(route + query(params), { headers: HEADERS }))).arrayBuffer());
}

export async function postBinary(route, body) {
  const r = await fetch(route, { method: 'POST', headers: { ...HEADERS, 'Content-Type': 'application/json' },
    body: JSON.stringify(body) });
  return decode(await (await checked(r)).arrayBuffer());
}

// a slice picture (an object URL of the PNG), its pixel -> world map and where the other planes cut it
export async function getSlice(params) {
  const r = await checked(await fetch('slice.png' + query(params), { headers: HEADERS }));
  return { url: URL.createObjectURL(await r.blob()), map: JSON.parse(r.headers.get('X-Slice-Map')),
    cross: JSON.parse(r.headers.get('X-Slice-Cross')) };
}

// {header, arrays: {name: {data: TypedArray, shape}}}
export function decode(buf) {
  const bytes = new Uint8Array(buf);
  if (String.fromCharCode(...bytes.subarray(0, 4)) !== 'VOLW') throw new Error('not a volumen message');
  const n = new DataView(buf).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(8, 8 + n)));
  const base = 8 + n, arrays = {};
  for (const [name, d] of Object.entries(header.arrays)) {
    const T = TYPES[d.dtype];
    arrays[name] = { data: new T(buf, base + d.offset, d.nbytes / T.BYTES_PER_ELEMENT), shape: d.shape };
  }
  delete header.arrays;
  return { header, arrays };
}
