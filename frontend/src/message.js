// The message bar (#message): neutral text, server errors and "disconnected".

const ERROR_SETTLE_MS = 5000;

/**
 * `#message`: neutral text, an error (class "error") or "disconnected". An error stays until a
 * later status/scene (`settle`) lets it fall back to the neutral text 5 s after that.
 */
export function createMessageBar(node) {
  let mode = "neutral";
  let neutralText = "connecting…";
  let timer = null;

  function render(text) {
    node.classList.toggle("error", mode === "error");
    node.classList.toggle("disconnected", mode === "disconnected");
    node.textContent = text;
  }
  function stopTimer() {
    clearTimeout(timer);
    timer = null;
  }

  return {
    neutral(text) {
      neutralText = text;
      if (mode === "neutral") render(text);
    },
    error(text) {
      if (mode === "disconnected") return;
      stopTimer();
      mode = "error";
      render(text);
    },
    disconnected() {
      stopTimer();
      mode = "disconnected";
      render("disconnected");
    },
    settle() {
      if (mode !== "error" || timer !== null) return;
      timer = setTimeout(() => {
        timer = null;
        mode = "neutral";
        render(neutralText);
      }, ERROR_SETTLE_MS);
    },
    destroy: stopTimer,
  };
}
