"""What FaçAID reads from a photo: its facade's corners (`vanishing`, `rectify`), how alike two places of it
look (`appearance`) and the shifts it repeats by (`repeats`, which `facaid.completion.copies` carries a drawn
unit along); and
photo-like pictures of generated facades to test them with (`photolike`)."""
