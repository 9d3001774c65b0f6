// The procedure page's forms that need no tree: the downloads' scale (a facade width in metres), the delete form's
// question, the overlay's opacity and what sharing will show.

export function mountForms() {
  // The CGA rules and the 3D models (the links marked data-scaled) are in metres: a facade width the user knows sets
  // their scale (metres per pixel of the saved procedure); left empty, the server's default (the page says which).
  const widthField = document.getElementById("width-m");
  // the server's bound
  if (widthField) widthField.max = Number(widthField.dataset.maxScale) * Number(widthField.dataset.px);
  widthField?.addEventListener("input", () => {
    const metres = Number(widthField.value);
    const scaled = widthField.value !== "" && Number.isFinite(metres) && metres > 0 && metres <= Number(widthField.max);
    widthField.setCustomValidity(widthField.value === "" || scaled ? "" : `a width from 0.1 to ${widthField.max} m`);
    widthField.reportValidity();
    for (const link of document.querySelectorAll("a[data-scaled]")) {
      const base = link.getAttribute("href").split("?")[0];
      link.setAttribute("href", scaled ? `${base}?metres_per_pixel=${metres / Number(widthField.dataset.px)}` : base);
    }
  });

  // a form that asks first (delete): its handler is here, as the site's Content-Security-Policy refuses inline ones
  for (const form of document.querySelectorAll("form[data-confirm]")) {
    form.addEventListener("submit", (e) => { if (!confirm(form.dataset.confirm)) e.preventDefault(); });
  }
  document.getElementById("opacity")?.addEventListener("input", (e) => {
    document.getElementById("overlay").style.opacity = e.target.value;
  });

  // Sharing the procedure asks whether to share its photo too (the question shows while the choice is not private),
  // and says what viewers will see once saved, for the choice made (sharing.previews).
  const shareVisibility = document.querySelector("#visibility-form select[name=visibility]");
  if (shareVisibility) {
    const sharePhoto = document.getElementById("share-photo");
    const willSee = document.getElementById("viewers-will-see");
    const previews = JSON.parse(document.getElementById("sharing-previews").textContent);
    const ask = () => {
      if (sharePhoto) sharePhoto.hidden = shareVisibility.value === "private";
      const photo = sharePhoto && !sharePhoto.hidden && sharePhoto.querySelector("input").checked;
      const changed = shareVisibility.value !== shareVisibility.dataset.saved || photo;
      willSee.hidden = !changed;
      willSee.textContent = changed ? `Once saved: ${previews[shareVisibility.value + (photo ? "+photo" : "")]}` : "";
    };
    shareVisibility.dataset.saved = shareVisibility.value;
    shareVisibility.addEventListener("change", ask);
    if (sharePhoto) sharePhoto.querySelector("input").addEventListener("change", ask);
    ask();
  }
}
