"""What FaçAID reads from a photo, opened as a viewer shows it (`files`): its facade's corners (`vanishing`,
`rectify`), how alike two places of it look (`appearance`) and the shifts it repeats by (`repeats`, along which
`facaid.completion.copies` carries a drawn unit); and photo-like pictures of generated facades to test them with
(`photolike`)."""
