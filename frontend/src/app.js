// Entry point of the `collidium view` page: connects to the server's /ws WebSocket and mounts the
// viewer in #collidium-root; `window.collidiumViewer` is the test hook object.
import "uplot/dist/uPlot.min.css";
import "./viewer.css";
import { websocketTransport } from "./transport.js";
import { mountViewer } from "./viewer.js";

function socketUrl() {
  const scheme = window.location.protocol === "https:" ? "wss:" : "ws:";
  return `${scheme}//${window.location.host}/ws`;
}

function start() {
  const root = document.getElementById("collidium-root");
  if (!root) {
    console.error("collidium: no #collidium-root element on the page");
    return;
  }
  root.classList.add("collidium-page");
  const viewer = mountViewer(root, websocketTransport(socketUrl()));
  window.collidiumViewer = viewer.hooks;
}

if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start, { once: true });
else start();
