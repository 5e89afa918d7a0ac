"""An importer's FMI 3.0 intermediateUpdate callback, as the FMI 3.0 tests of both models pass
it to FMU3Slave.instantiate."""


class IntermediateUpdate:
    """Records each call (intermediateUpdateTime and the flags intermediateVariableSetRequested,
    intermediateVariableGetAllowed, intermediateStepFinished, canReturnEarly) and requests the
    early return, at the time of the call, at call number `request_at` (1 the first; None:
    never)."""

    def __init__(self, request_at=None):
        self.calls, self.request_at = [], request_at

    def __call__(self, env, t, set_requested, get_allowed, step_finished, can_return_early, requested, return_time):
        self.calls.append((t, set_requested, get_allowed, step_finished, can_return_early))
        if len(self.calls) == self.request_at:
            requested[0] = True
            return_time[0] = t

    def times(self):
        return [c[0] for c in self.calls]

    def flags(self):
        """The distinct sets of flags the calls had."""
        return {c[1:] for c in self.calls}
