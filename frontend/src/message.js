// The message bar (#message): neutral text, server errors and "disconnected".

const ERROR_SETTLE_MS = 5000;

/**
 * `#message`: neutral text, an error (class "error") or "disconnected". An error stays until a
 * later status/scene (`settle`) lets it fall back to the neutral text 5 s after that. A lasting
 * error (`lasting`, e.g. no WebGL) takes the neutral text's place for good.
 */
export function createMessageBar(node) {
  let mode = "neutral";
  let neutralText = "connecting…";
  let lastingText = null;
  let timer = null;

  function render(kind, text) {
    node.classList.toggle("error", kind === "error");
    node.classList.toggle("disconnected", kind === "disconnected");
    node.textContent = text;
  }
  function renderNeutral() {
    if (lastingText === null) render("neutral", neutralText);
    else render("error", lastingText);
  }
  function stopTimer() {
    clearTimeout(timer);
    timer = null;
  }

  return {
    neutral(text) {
      neutralText = text;
      if (mode === "neutral") renderNeutral();
    },
    error(text) {
      if (mode === "disconnected") return;
      stopTimer();
      mode = "error";
      render("error", text);
    },
    /** An error that does not settle: shown whenever the neutral text would be. */
    lasting(text) {
      lastingText = text;
      if (mode === "neutral") renderNeutral();
    },
    disconnected() {
      stopTimer();
      mode = "disconnected";
      render("disconnected", "disconnected");
    },
    settle() {
      if (mode !== "error" || timer !== null) return;
      timer = setTimeout(() => {
        timer = null;
        mode = "neutral";
        renderNeutral();
      }, ERROR_SETTLE_MS);
    },
    destroy: stopTimer,
  };
}
