// Entry point of the Jupyter anywidget: the same viewer inside the widget's element, talking to
// the kernel through the widget model. `el.collidiumViewer` is the test hook object.
import "uplot/dist/uPlot.min.css";
import "./viewer.css";
import { widgetTransport } from "./transport.js";
import { mountViewer } from "./viewer.js";

export default {
  render({ model, el }) {
    el.classList.add("collidium-widget");
    const viewer = mountViewer(el, widgetTransport(model));
    el.collidiumViewer = viewer.hooks;
    return () => {
      viewer.destroy();
      el.classList.remove("collidium-widget");
      delete el.collidiumViewer;
    };
  },
};
