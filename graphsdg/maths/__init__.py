"""Pure numpy maths that every room can use. Used by stage/, sim/, render/, compat/ and io/; imports nothing of
graphsdg's."""
