// Tiny DOM helpers: the viewer builds its own elements and keeps references to them, so it never
// looks anything up globally (two widgets may share a page and repeat the same ids).

/** Creates `tag` with attributes/properties from `props` and appends `children` (nodes or text). */
export function element(tag, props = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(props)) {
    if (value === undefined || value === null || value === false) continue;
    if (key === "className") node.className = value;
    else if (key === "text") node.textContent = value;
    else if (key in node && typeof value !== "string") node[key] = value;
    else node.setAttribute(key, value === true ? "" : String(value));
  }
  for (const child of [].concat(children)) {
    if (child !== null && child !== undefined) node.append(child);
  }
  return node;
}

/** A labelled control: `<label class="field"><span>text</span>control</label>`. */
export function labelled(text, control, className = "field") {
  return element("label", { className }, [element("span", { text }), control]);
}
