"""What FaçAID reads from a photo, opened as a viewer shows it (`files`, `metadata`, `webp`): its facade's corners
(`corners`: the proposal, from the vanishing points of `vanishing`, moved off the no-data wedges of `nodata`), the
warp that rectifies it (`rectify`), how alike two places of it look (`appearance`) and the shifts it repeats by
(`repeats`, along which `facaid.completion.copies` carries a drawn unit); and photo-like pictures of generated
facades to test them with (`photolike`)."""
