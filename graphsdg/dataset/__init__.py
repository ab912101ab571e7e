"""Reading, checking and looking at datasets graphsdg wrote."""
