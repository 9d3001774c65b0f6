"""What FaçAID reads from a photo: its facade's corners (`vanishing`, `rectify`), how alike two places of it
look (`appearance`), the shifts it repeats by and the copies of a drawn unit (`repeats`, `copies`); and
photo-like pictures of generated facades to test them with (`photolike`)."""
