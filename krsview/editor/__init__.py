"""The tree editor: handles (what can be grabbed, and the edit a drag makes), panels, and the
editor window (``window``) built on the viewer; its document lives in ``krsview.document``."""
