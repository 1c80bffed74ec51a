"""The tree editor: a document that owns the scene, its file, the undo history and the saved
version (``document``, ``history``), and the editor window on top of the viewer (``app``)."""
