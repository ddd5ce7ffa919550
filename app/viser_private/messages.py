"""The messages viser 1.1's own client sends, as strict, bounded msgspec structs: the wire's
allow-list (:data:`ALLOWED`) and its decoder (:func:`client_message`). Part of the one adapter
to viser's internals (:mod:`poinsot.app.viser_private`, whose docstring has the inventory):
each struct mirrors a class of ``viser._messages``, field for field, checked by
:func:`poinsot.app.viser_private.check`."""

from __future__ import annotations

from typing import Annotated, Any, Union

import msgspec

# -- messages ----------------------------------------------------------------------------------
# The messages viser 1.1's own client sends, as msgspec structs with the fields of viser's
# dataclasses (same names, same order), typed strictly and bounded: a text no longer than a
# browser's would be, a number finite and of a sane size, no nesting a browser never sends.
_NUM = 1e9
Num = Annotated[float, msgspec.Meta(ge=-_NUM, le=_NUM)]
Count = Annotated[int, msgspec.Meta(ge=0, le=1 << 40)]
Id = Annotated[str, msgspec.Meta(max_length=256)]
Text = Annotated[str, msgspec.Meta(max_length=65_536)]
Scalar = bool | int | float | Text | None
#: A widget value: a scalar, or a flat list (vectors, colours, multi-sliders).
Value = Scalar | Annotated[list[Scalar], msgspec.Meta(max_length=64)]
#: One part of an upload [bytes] (viser's client sends far smaller ones).
MAX_PART_BYTES = 4_000_000
#: A rendered picture (viser's own message limit).
MAX_RENDER_BYTES = 50 * 1024 * 1024
V3 = tuple[Num, Num, Num]
V2 = tuple[Num, Num]


def _message(name: str) -> dict[str, Any]:
    return {"tag_field": "type", "tag": name, "forbid_unknown_fields": True, "frozen": True}


class ViewerCamera(msgspec.Struct, **_message("ViewerCameraMessage")):
    wxyz: tuple[Num, Num, Num, Num]
    position: V3
    fov: Num
    near: Num
    far: Num
    image_height: Num  # a canvas's size (not always a whole number)
    image_width: Num
    look_at: V3
    up_direction: V3


class GuiUpdate(msgspec.Struct, **_message("GuiUpdateMessage")):
    uuid: Id
    updates: Annotated[dict[Id, Value], msgspec.Meta(max_length=16)]


class GuiButtonHold(msgspec.Struct, **_message("GuiButtonHoldMessage")):
    uuid: Id
    frequency: Num


class GuiFormSubmit(msgspec.Struct, **_message("GuiFormSubmitMessage")):
    uuid: Id


class GuiFormDirty(msgspec.Struct, **_message("GuiFormDirtyMessage")):
    uuid: Id


class CommandTrigger(msgspec.Struct, **_message("CommandTriggerMessage")):
    uuid: Id


class FileTransferStartUpload(msgspec.Struct, **_message("FileTransferStartUpload")):
    source_component_uuid: Id
    transfer_uuid: Id
    filename: Text
    mime_type: Id
    part_count: Count
    size_bytes: Count


class FileTransferPart(msgspec.Struct, **_message("FileTransferPart")):
    source_component_uuid: Id | None
    transfer_uuid: Id
    part_index: Count
    content: Annotated[bytes, msgspec.Meta(max_length=MAX_PART_BYTES)]


class FileTransferPartAck(msgspec.Struct, **_message("FileTransferPartAck")):
    source_component_uuid: Id | None
    transfer_uuid: Id
    transferred_bytes: Count
    total_bytes: Count


class ScenePointer(msgspec.Struct, **_message("ScenePointerMessage")):
    event_type: Id
    ray_origin: V3 | None
    ray_direction: V3 | None
    screen_pos: Annotated[list[V2], msgspec.Meta(max_length=16)]
    modifier: Id | None


class SceneNodeClick(msgspec.Struct, **_message("SceneNodeClickMessage")):
    name: Text
    instance_index: Count | None
    ray_origin: V3
    ray_direction: V3
    screen_pos: V2
    modifier: Id | None
    owner: Id = ""


class SceneNodeDrag(msgspec.Struct, **_message("SceneNodeDragMessage")):
    phase: Id
    name: Text
    instance_index: Count | None
    start_position: V3
    start_screen_pos: V2
    end_position: V3
    end_screen_pos: V2
    button: Id
    modifier: Id | None
    owner: Id = ""


class TransformControlsUpdate(msgspec.Struct, **_message("TransformControlsUpdateMessage")):
    name: Text
    wxyz: tuple[Num, Num, Num, Num]
    position: V3
    owner: Id = ""


class TransformControlsDragStart(msgspec.Struct, **_message("TransformControlsDragStartMessage")):
    name: Text
    owner: Id = ""


class TransformControlsDragEnd(msgspec.Struct, **_message("TransformControlsDragEndMessage")):
    name: Text
    owner: Id = ""


class LocalStorageGetItemResponse(msgspec.Struct, **_message("LocalStorageGetItemResponseMessage")):
    value: Text | None
    error: Text | None
    request_uuid: Id


class GetRenderResponse(msgspec.Struct, **_message("GetRenderResponseMessage")):
    payload: Annotated[bytes, msgspec.Meta(max_length=MAX_RENDER_BYTES)]
    render_uuid: Id


#: What a client may send: viser's message class name -> its struct. ``ShareUrlRequest`` and
#: ``ShareUrlDisconnect`` are left out on purpose (no student opens a public tunnel).
ALLOWED: dict[str, type[msgspec.Struct]] = {
    struct.__struct_config__.tag: struct  # type: ignore[misc]
    for struct in (
        ViewerCamera,
        GuiUpdate,
        GuiButtonHold,
        GuiFormSubmit,
        GuiFormDirty,
        CommandTrigger,
        FileTransferStartUpload,
        FileTransferPart,
        FileTransferPartAck,
        ScenePointer,
        SceneNodeClick,
        SceneNodeDrag,
        TransformControlsUpdate,
        TransformControlsDragStart,
        TransformControlsDragEnd,
        GetRenderResponse,
        LocalStorageGetItemResponse,
    )
}
_DECODER: msgspec.msgpack.Decoder[Any] = msgspec.msgpack.Decoder(
    Union[tuple(ALLOWED.values())]  # noqa: UP007 (a union built from a tuple at run time)
)


class _Envelope(msgspec.Struct):
    type: str


class Refused(ValueError):
    """A message that is not one viser's client sends; ``kind`` names its type as sent."""

    def __init__(self, kind: str, why: str) -> None:
        super().__init__(why)
        self.kind = kind


def client_message(raw: object) -> msgspec.Struct:
    """``raw`` decoded as one of the :data:`ALLOWED` messages, or :class:`Refused` (with the
    type it claimed, and why). Never deeper than the message's own fields: a value nested
    where a number belongs fails at its first level."""
    if not isinstance(raw, bytes):
        raise Refused("text frame", "not a binary frame")
    try:
        message: msgspec.Struct = _DECODER.decode(raw)
    except (msgspec.DecodeError, msgspec.ValidationError, ValueError, RecursionError) as exc:
        raise Refused(message_type(raw), str(exc)[:120]) from None
    return message


def message_type(raw: bytes) -> str:
    """The type a message claims (at most 40 characters), else what it is."""
    try:
        kind = msgspec.msgpack.decode(raw, type=_Envelope).type
    except (msgspec.DecodeError, msgspec.ValidationError, ValueError, RecursionError):
        return "not a message"
    return kind[:40] if kind.isprintable() else repr(kind)[:40]
