"""Every call that differs between the supported Blender lines (4.5 LTS and 5.2 LTS)."""


def modifier_input(modifier, identifier):
    """A geometry-nodes modifier's input value (ID properties up to 5.1, ``properties`` after)."""
    properties = getattr(modifier, "properties", None)
    if properties is not None and hasattr(properties, "inputs"):
        return getattr(properties.inputs, identifier).value
    return modifier.get(identifier)


def set_modifier_input(modifier, identifier, value):
    properties = getattr(modifier, "properties", None)
    if properties is not None and hasattr(properties, "inputs"):
        getattr(properties.inputs, identifier).value = value
    else:
        modifier[identifier] = value
