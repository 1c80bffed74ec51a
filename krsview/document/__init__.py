"""The document: one scene with its file, undo history, saved version, autosave and
recovery; the one seam every scene change goes through, for the viewer and the editor alike."""

from .document import ConflictError, Document
from .history import History

__all__ = ["ConflictError", "Document", "History"]
