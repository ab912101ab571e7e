"""Pure numpy maths that every room (stage/, sim/, render/, compat/, io/) can use; imports nothing of graphsdg's."""
