"""The plan file: its format and schema (``plan_file``, ``plan_doc``, ``segment``,
``cell_record``, ``json_fields``), its independent verification (``verify`` and its parts
``verify_flight``, ``verify_clearance``, ``verify_report``) and its export to a controller
(``export``, ``servo_command``)."""
