"""The kitchen: cook orders and table spots (``cook``), the motions a schedule uses
(``motions``), the cook-window scheduler (``schedule``) and planning ahead (``prefetch``)."""
