// The page's access to contactd's API (docs/server.md): every request carries the bearer token the user gave
// (kept in this browser's localStorage), state changes carry X-Requested-With (the server's cross-site rule),
// and an error answer (a problem document) becomes an ApiError whose lines say what went wrong and where.
// URLs are relative to the page, so the page also works behind a proxy that serves it under a path prefix.

const TOKEN_KEY = "contactd.token";

export function getToken() {
  try {
    return window.localStorage.getItem(TOKEN_KEY) || "";
  } catch (e) {
    return "";  // storage disabled: no token kept
  }
}

export function setToken(token) {
  try {
    if (token) window.localStorage.setItem(TOKEN_KEY, token);
    else window.localStorage.removeItem(TOKEN_KEY);
  } catch (e) {
    // storage disabled: the token lasts as long as the page
  }
  memoryToken = token;
}

let memoryToken = null;

function currentToken() {
  return memoryToken !== null ? memoryToken : getToken();
}

export class ApiError extends Error {
  // status: the HTTP status (0: no answer); lines: one sentence per problem, with its JSON pointer for an invalid job.
  constructor(status, lines, doc) {
    super(lines.join("\n"));
    this.status = status;
    this.lines = lines;
    this.doc = doc || null;
  }
}

export function headers(extra = {}) {
  const h = {...extra};
  const token = currentToken();
  if (token) h["Authorization"] = "Bearer " + token;
  return h;
}

// The lines of an error answer: the problem document's detail and, for an invalid job, every error with its pointer.
function problemLines(status, doc, text) {
  if (doc && typeof doc === "object") {
    const lines = [];
    const errors = Array.isArray(doc.errors) ? doc.errors : [];
    if (errors.length) {
      for (const e of errors) lines.push(`${e.pointer === "" ? "(document)" : e.pointer}: ${e.message}`);
    } else {
      lines.push(`${status} ${doc.title || ""}: ${doc.detail || ""}`.trim());
    }
    if (status === 401) lines.push("Enter the server's token in the Bearer token field at the top.");
    return lines;
  }
  return [`${status}: ${(text || "no answer").slice(0, 300)}`];
}

export async function errorFrom(response) {
  const text = await response.text().catch(() => "");
  let doc = null;
  try {
    doc = JSON.parse(text);
  } catch (e) {
    doc = null;
  }
  return new ApiError(response.status, problemLines(response.status, doc, text), doc);
}

// fetch() with the token; `body` (a string) is sent as JSON. Returns the parsed JSON answer (null for 204).
export async function api(path, {method = "GET", body = undefined, signal = undefined} = {}) {
  const h = headers({"Accept": "application/json"});
  if (body !== undefined) h["Content-Type"] = "application/json";
  if (method !== "GET") h["X-Requested-With"] = "contactd-web";
  let response;
  try {
    response = await fetch(path, {method, body, headers: h, signal, cache: "no-store"});
  } catch (e) {
    if (e.name === "AbortError") throw e;
    throw new ApiError(0, ["cannot reach the server (is contactd running?)"]);
  }
  if (!response.ok) throw await errorFrom(response);
  if (response.status === 204) return null;
  const text = await response.text();
  try {
    return JSON.parse(text);
  } catch (e) {
    throw new ApiError(response.status, ["the server's answer is not JSON: " + text.slice(0, 200)]);
  }
}

// Downloads `path` with the token and saves it under `filename` (a link cannot send a header).
export async function download(path, filename) {
  const response = await fetch(path, {headers: headers(), cache: "no-store"});
  if (!response.ok) throw await errorFrom(response);
  const blob = await response.blob();
  const url = URL.createObjectURL(blob);
  const a = document.createElement("a");
  a.href = url;
  a.download = filename;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60000);
  return blob.size;
}
