// The view's parts without a browser: the photo's brightness and contrast as a canvas filter.
import assert from "node:assert/strict";
import {test} from "node:test";

import {photoFilter} from "../editor/tools/view.js";

test("photo filter: none at the photo's own levels, the factors otherwise, kept inside 0.2..4", () => {
  assert.equal(photoFilter(), "none");
  assert.equal(photoFilter({brightness: 1, contrast: 1}), "none");
  assert.equal(photoFilter({brightness: 1.8}), "brightness(1.8) contrast(1)");
  assert.equal(photoFilter({brightness: 9, contrast: 0}), "brightness(4) contrast(0.2)");
  assert.equal(photoFilter({brightness: NaN, contrast: 1.5}), "brightness(1) contrast(1.5)");
});
