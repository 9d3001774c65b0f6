// The procedure page's variations without a browser: what a variant's card says it is.
import assert from "node:assert/strict";
import {test} from "node:test";

import {variantCaption} from "../procedure/variations.js";

test("a variant's caption says its counts and what made it, not its kind and size", () => {
  const v = (variation, counts, w = 654.4, h = 797) => ({width: w, height: h, meta: {variation, counts}});
  assert.equal(variantCaption(v("resize", {floors: 5, bays: 9}), ""), "5 upper floors, 9 tiles a floor · resized to 654 × 797 px");
  assert.equal(variantCaption(v("count", {floors: 1, bays: 1}), ""), "1 upper floor, 1 tile a floor · one repeat's count changed");
  assert.equal(variantCaption(v("ranges", {floors: 7}), "upper floors 7"), "7 upper floors · upper floors 7");
  assert.equal(variantCaption({width: 10, height: 10}, ""), "a variant");
});
