// Two transports with one interface, so the viewer does not care where it runs: a WebSocket (the
// `collidium view` page) and an anywidget model (Jupyter). JSON messages arrive as objects,
// binary frames as ArrayBuffers.

/** Listener lists for the transport events. */
function createEvents() {
  const listeners = { message: [], frame: [], open: [], close: [] };
  return {
    on(name, callback) {
      listeners[name].push(callback);
    },
    emit(name, value) {
      for (const callback of listeners[name]) callback(value);
    },
  };
}

/** The transport's public face over `events` and the two send functions. */
function transportInterface(events, sendRaw, send, close) {
  return {
    send,
    sendRaw,
    onMessage: (callback) => events.on("message", callback),
    onFrame: (callback) => events.on("frame", callback),
    onClose: (callback) => events.on("close", callback),
    onOpen: (callback) => events.on("open", callback),
    close,
  };
}

/** Parses a text message; a malformed one is reported and dropped, never thrown. */
function parseMessage(text) {
  try {
    const message = JSON.parse(text);
    if (message && typeof message.type === "string") return message;
  } catch {
    // fall through to the warning
  }
  console.warn("collidium: ignoring a malformed message", text.slice(0, 200));
  return null;
}

/** A WebSocket transport to `url`; binary messages are frames. */
export function websocketTransport(url) {
  const events = createEvents();
  const socket = new WebSocket(url);
  socket.binaryType = "arraybuffer";

  socket.addEventListener("open", () => events.emit("open"));
  socket.addEventListener("close", () => events.emit("close"));
  socket.addEventListener("message", (event) => {
    if (typeof event.data !== "string") {
      events.emit("frame", event.data);
      return;
    }
    const message = parseMessage(event.data);
    if (message) events.emit("message", message);
  });

  // Sending on a socket that is not open would throw; the page shows "disconnected" instead.
  const sendRaw = (text) => {
    if (socket.readyState === WebSocket.OPEN) socket.send(text);
  };
  return transportInterface(
    events,
    sendRaw,
    (message) => sendRaw(JSON.stringify(message)),
    () => socket.close(),
  );
}

/** An ArrayBuffer holding exactly the bytes of a DataView, typed array or ArrayBuffer. */
export function toArrayBuffer(data) {
  if (data instanceof ArrayBuffer) return data;
  if (ArrayBuffer.isView(data)) {
    const whole = data.byteOffset === 0 && data.byteLength === data.buffer.byteLength;
    return whole ? data.buffer : data.buffer.slice(data.byteOffset, data.byteOffset + data.byteLength);
  }
  return null;
}

/**
 * An anywidget transport: custom messages from the kernel arrive on "msg:custom"; a content of
 * type "frame" carries the binary frame in buffers[0]. The model is connected from the start, so
 * "open" fires (asynchronously) for every onOpen callback.
 */
export function widgetTransport(model) {
  const events = createEvents();
  let open = true;

  const handleCustom = (content, buffers) => {
    if (!open || !content || typeof content.type !== "string") return;
    if (content.type !== "frame") {
      events.emit("message", content);
      return;
    }
    const frame = buffers && buffers.length ? toArrayBuffer(buffers[0]) : null;
    if (frame) events.emit("frame", frame);
    else console.warn("collidium: frame message without a binary buffer");
  };
  model.on("msg:custom", handleCustom);

  const transport = transportInterface(
    events,
    (text) => open && model.send({ type: "raw", text }),
    (message) => open && model.send(message),
    () => {
      if (!open) return;
      open = false;
      model.off("msg:custom", handleCustom);
      events.emit("close");
    },
  );
  transport.onOpen = (callback) => queueMicrotask(() => open && callback());
  return transport;
}
