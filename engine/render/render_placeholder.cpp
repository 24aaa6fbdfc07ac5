// render: sources land here
